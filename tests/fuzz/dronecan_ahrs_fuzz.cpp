// Fuzz target: the DroneCAN ahrs.Solution decoder (drivers/src/dronecan_ahrs_decoder.cpp),
// frames from three source nodes. Checks in can_decoder_fuzz.hpp; here also: no more valid
// transfers than complete ones (frames counts transfers whose CRC matched, and single frames).
#include <cstdlib>

#include "can_decoder_fuzz.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using posefair::drivers::CanFrame;
  static const std::uint32_t ids[] = {CanFrame::kEffFlag | (16u << 24) | (1000u << 8) | 10u,
                                      CanFrame::kEffFlag | (16u << 24) | (1000u << 8) | 11u,
                                      CanFrame::kEffFlag | (1000u << 8) | 127u};
  const auto r = posefair::testing::fuzz_can_decoder(posefair::drivers::make_dronecan_ahrs_decoder, {}, {data, size}, ids,
                                                     CanFrame::kEffFlag | (1001u << 8) | 10u);
  if (r.counters.frames + r.counters.bad_checksum > r.frame_counters.received) std::abort();
  return 0;
}
