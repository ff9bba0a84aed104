// Fuzz target: the Yost 3-Space decoder (the default header 0x4F; and every header field, 0x7F,
// with 20 data bytes). Any bytes: no crash and no exception; the samples and counters do not
// depend on how the bytes are cut (whole, split in two at a point chosen from the data, and in
// three); every sample is a finite unit quaternion; every byte is counted. abort() on any
// difference.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <initializer_list>
#include <utility>
#include <vector>

#include "posefair/drivers/yost_decoder.hpp"

namespace {

using posefair::drivers::DecodedSample;
using posefair::drivers::DecoderCounters;
using posefair::drivers::DecoderOptions;

struct Recorder final : posefair::drivers::DecodedSink {
  std::vector<DecodedSample> samples;
  void on_sample(const DecodedSample& s) override { samples.push_back(s); }
};

struct Result {
  std::vector<DecodedSample> samples;
  DecoderCounters counters;
};

Result run(const DecoderOptions& options, const std::uint8_t* data, std::size_t size, std::initializer_list<std::size_t> pieces) {
  auto d = posefair::drivers::make_yost_decoder(options);
  Recorder r;
  std::size_t at = 0;
  for (const std::size_t n : pieces) {
    d->feed({data + at, n}, r);
    at += n;
  }
  d->feed({data + at, size - at}, r);
  return {r.samples, d->counters()};
}

bool same(const Result& a, const Result& b) {
  if (!(a.counters == b.counters) || a.samples.size() != b.samples.size()) return false;
  for (std::size_t k = 0; k < a.samples.size(); ++k)
    if (a.samples[k].orientation.coeffs() != b.samples[k].orientation.coeffs() || a.samples[k].flags != b.samples[k].flags)
      return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the input: the cut points
  for (std::size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  const std::size_t a = static_cast<std::size_t>(h % (size + 1));
  const std::size_t b = static_cast<std::size_t>((h >> 32) % (size + 1));
  for (const auto& [header, length] : {std::pair{"0x4F", "16"}, std::pair{"0x7F", "20"}}) {
    DecoderOptions options;
    options.yost_header = header;
    options.yost_data_length = length;
    const Result whole = run(options, data, size, {});
    if (whole.counters.bytes != size) std::abort();
    if (!same(whole, run(options, data, size, {a}))) std::abort();
    if (!same(whole, run(options, data, size, {std::min(a, b), std::max(a, b) - std::min(a, b)}))) std::abort();
    for (const DecodedSample& s : whole.samples)
      if (!s.orientation.coeffs().allFinite() || std::abs(s.orientation.norm() - 1.0) > 1e-9) std::abort();
  }
  return 0;
}
