// Fuzz target: the Xsens MTi CAN decoder (drivers/src/xsens_can_decoder.cpp), default
// identifiers. Checks in can_decoder_fuzz.hpp.
#include "can_decoder_fuzz.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::uint32_t ids[] = {0x005, 0x006, 0x021};
  posefair::testing::fuzz_can_decoder(posefair::drivers::make_xsens_can_decoder, {}, {data, size}, ids, 0x022);
  return 0;
}
