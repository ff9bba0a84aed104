// Fuzz target: the Xsens MTData2 decoder (drivers/src/xsens_decoder.cpp). The input is fed
// whole to one decoder and, to another, in three pieces cut at points the input itself picks;
// both must give the same samples and counters (abort() otherwise), and every sample must be
// a finite unit quaternion with a finite device time.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "decoder_fuzz.hpp"
#include "posefair/drivers/xsens_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::size_t cut1 = 0, cut2 = 0;
  if (size > 0) {
    cut1 = (data[0] * 257u + data[size / 2]) % (size + 1);
    cut2 = cut1 + (data[size - 1] * 131u) % (size - cut1 + 1);
  }
  const auto whole = posefair::testing::fuzz_decoder(posefair::drivers::make_xsens_decoder, {}, {data, size}, {{cut1, cut2}});
  for (const auto& s : whole.samples)
    if (!posefair::testing::finite_unit(s.orientation, 1e-12) || !std::isfinite(s.device_time)) std::abort();
  return 0;
}
