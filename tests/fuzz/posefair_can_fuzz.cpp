// Fuzz target: posefair's CAN layout decoder (drivers/src/posefair_can_decoder.cpp), base
// 0x200. Checks in can_decoder_fuzz.hpp; here also: positions and raw readings within their
// int16 ranges.
#include <cmath>
#include <cstdlib>

#include "can_decoder_fuzz.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::uint32_t ids[] = {0x200, 0x201, 0x202, 0x203};
  const auto r = posefair::testing::fuzz_can_decoder(posefair::drivers::make_posefair_can_decoder, {}, {data, size}, ids, 0x204);
  for (const auto& s : r.samples)
    if (s.position.cwiseAbs().maxCoeff() > 32.768 || s.gyro.cwiseAbs().maxCoeff() > 32.768 ||
        s.accel.cwiseAbs().maxCoeff() > 327.68 || s.mag.cwiseAbs().maxCoeff() > 327.68)
      std::abort();
  return 0;
}
