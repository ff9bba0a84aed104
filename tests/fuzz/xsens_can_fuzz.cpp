// Fuzz target: the Xsens MTi CAN decoder (drivers/src/xsens_can_decoder.cpp), default
// identifiers, without and with the raw messages (xsens_raw: rate of turn, acceleration,
// magnetic field gathered per group). Checks in can_decoder_fuzz.hpp.
#include <string>
#include <vector>

#include "can_decoder_fuzz.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::uint32_t ids[] = {0x005, 0x006, 0x021};
  posefair::testing::fuzz_can_decoder(posefair::drivers::make_xsens_can_decoder, {}, {data, size}, ids, 0x022);
  static const std::uint32_t raw_ids[] = {0x005, 0x006, 0x021, 0x032, 0x034, 0x041};
  static const posefair::OptionMap raw{
      {"xsens_raw", std::vector<std::string>{"rate_of_turn", "acceleration", "magnetic_field"}}};
  const auto r = posefair::testing::fuzz_can_decoder(posefair::drivers::make_xsens_can_decoder, raw, {data, size}, raw_ids, 0x022);
  for (const auto& s : r.samples)
    if (!s.gyro.allFinite() || !s.accel.allFinite() || !s.mag.allFinite()) std::abort();
  return 0;
}
