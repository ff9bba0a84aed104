// Fuzz target: posefair's CAN layout decoder (drivers/src/posefair_can_decoder.cpp), base
// 0x200. Checks in can_decoder_fuzz.hpp; here also: positions within the int16 mm range.
#include <cmath>
#include <cstdlib>

#include "can_decoder_fuzz.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::uint32_t ids[] = {0x200, 0x201, 0x202};
  const auto r = posefair::testing::fuzz_can_decoder(posefair::drivers::make_posefair_can_decoder, {}, {data, size}, ids, 0x203);
  for (const auto& s : r.samples)
    if (s.position.cwiseAbs().maxCoeff() > 32.768) std::abort();
  return 0;
}
