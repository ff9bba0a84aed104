// Fuzz target: posefair's serial protocol decoder (drivers/src/posefair_serial_decoder.cpp).
// The input is fed whole to one decoder and, to another, in three pieces cut at points the
// input itself picks; both must give the same samples and counters (abort() otherwise), and
// every sample must be a finite unit quaternion with a finite device time and position.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "posefair/drivers/posefair_serial_decoder.hpp"

namespace {

struct Collector : posefair::drivers::DecodedSink {
  std::vector<posefair::drivers::DecodedSample> samples;
  void on_sample(const posefair::drivers::DecodedSample& s) override {
    if (!s.orientation.coeffs().allFinite() || std::abs(s.orientation.norm() - 1.0) > 1e-12 ||
        !std::isfinite(s.device_time) || !s.position.allFinite())
      std::abort();
    samples.push_back(s);
  }
};

bool same(const posefair::drivers::DecodedSample& a, const posefair::drivers::DecodedSample& b) {
  return a.orientation.coeffs() == b.orientation.coeffs() && a.position == b.position && a.flags == b.flags &&
         a.device_time == b.device_time && a.frame_counter == b.frame_counter &&
         a.has_frame_counter == b.has_frame_counter;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto whole = posefair::drivers::make_posefair_serial_decoder();
  auto split = posefair::drivers::make_posefair_serial_decoder();
  Collector a, b;
  whole->feed({data, size}, a);
  std::size_t cut1 = 0, cut2 = 0;
  if (size > 0) {
    cut1 = (data[0] * 257u + data[size / 2]) % (size + 1);
    cut2 = cut1 + (data[size - 1] * 131u) % (size - cut1 + 1);
  }
  split->feed({data, cut1}, b);
  split->feed({data + cut1, cut2 - cut1}, b);
  split->feed({data + cut2, size - cut2}, b);
  if (!(whole->counters() == split->counters()) || a.samples.size() != b.samples.size()) std::abort();
  for (std::size_t k = 0; k < a.samples.size(); ++k)
    if (!same(a.samples[k], b.samples[k])) std::abort();
  if (whole->counters().bytes != size || whole->counters().samples != a.samples.size()) std::abort();
  return 0;
}
