// Fuzz target: the BNO08x UART-RVC decoder. Any bytes, fed whole and fed split in two at a point
// taken from the data, must give the same samples and counters, every sample a finite unit
// quaternion with a non-decreasing frame counter, and no crash, exception or out-of-bounds read.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "posefair/drivers/bno08x_rvc_decoder.hpp"

namespace {

using posefair::drivers::DecodedSample;

struct Collect : posefair::drivers::DecodedSink {
  std::vector<DecodedSample> samples;
  void on_sample(const DecodedSample& s) override { samples.push_back(s); }
};

bool same(const DecodedSample& a, const DecodedSample& b) {
  return a.orientation.coeffs() == b.orientation.coeffs() && a.position == b.position && a.flags == b.flags &&
         a.device_time == b.device_time && a.frame_counter == b.frame_counter &&
         a.has_frame_counter == b.has_frame_counter;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  posefair::drivers::DecoderOptions options;
  const std::span<const std::uint8_t> in(data, size);

  auto whole = posefair::drivers::make_bno08x_rvc_decoder(options);
  Collect a;
  whole->feed(in, a);

  std::size_t cut = 0;
  for (std::size_t i = 0; i < size && i < 8; ++i) cut = cut * 131 + data[size - 1 - i];
  cut = size > 0 ? cut % (size + 1) : 0;
  auto split = posefair::drivers::make_bno08x_rvc_decoder(options);
  Collect b;
  split->feed(in.first(cut), b);
  split->feed(in.subspan(cut), b);

  if (!(whole->counters() == split->counters()) || a.samples.size() != b.samples.size()) std::abort();
  if (whole->counters().bytes != size || whole->counters().samples != a.samples.size()) std::abort();
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    if (!same(a.samples[i], b.samples[i])) std::abort();
    const auto& q = a.samples[i].orientation;
    if (!q.coeffs().allFinite() || std::abs(q.norm() - 1.0) > 1e-9) std::abort();
    if (a.samples[i].flags != 0 || !a.samples[i].has_frame_counter) std::abort();
    if (i > 0 && a.samples[i].frame_counter < a.samples[i - 1].frame_counter) std::abort();
  }
  return 0;
}
