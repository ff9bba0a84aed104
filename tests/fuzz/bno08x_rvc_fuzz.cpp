// Fuzz target: the BNO08x UART-RVC decoder. Any bytes, fed whole and fed split in two at a point
// taken from the data, must give the same samples and counters, every sample a finite unit
// quaternion with its acceleration and a non-decreasing frame counter, and no crash, exception or out-of-bounds read.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "decoder_fuzz.hpp"
#include "posefair/drivers/bno08x_rvc_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::size_t cut = 0;
  for (std::size_t i = 0; i < size && i < 8; ++i) cut = cut * 131 + data[size - 1 - i];
  cut = size > 0 ? cut % (size + 1) : 0;
  const auto whole = posefair::testing::fuzz_decoder(posefair::drivers::make_bno08x_rvc_decoder, {}, {data, size}, {{cut}});
  for (std::size_t i = 0; i < whole.samples.size(); ++i) {
    const auto& s = whole.samples[i];
    if (!posefair::testing::finite_unit(s.orientation, 1e-9)) std::abort();
    if (s.flags != posefair::kHasAccel || !s.has_frame_counter) std::abort();
    if (i > 0 && s.frame_counter < whole.samples[i - 1].frame_counter) std::abort();
  }
  return 0;
}
