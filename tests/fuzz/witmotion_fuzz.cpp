// Fuzz target: the WitMotion decoder. Any bytes, fed whole and fed split in two at a point taken
// from the data, must give the same samples and counters, every sample a finite unit quaternion,
// and no crash, exception or out-of-bounds read. The last byte also picks witmotion_scalar.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "decoder_fuzz.hpp"
#include "posefair/drivers/witmotion_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const posefair::OptionMap options{
      {"witmotion_scalar", std::string((size > 0 && (data[size - 1] & 1)) ? "last" : "first")}};
  std::size_t cut = 0;
  for (std::size_t i = 0; i < size && i < 8; ++i) cut = cut * 131 + data[size - 1 - i];
  cut = size > 0 ? cut % (size + 1) : 0;
  const auto whole = posefair::testing::fuzz_decoder(posefair::drivers::make_witmotion_decoder, options, {data, size}, {{cut}});
  for (const auto& s : whole.samples) {
    if (!posefair::testing::finite_unit(s.orientation, 1e-9)) std::abort();
    if ((s.flags & posefair::kHasDeviceTime) && !std::isfinite(s.device_time)) std::abort();
  }
  return 0;
}
