// Decoding throughput of the DroneCAN ahrs.Solution decoder (drivers/src/dronecan_ahrs_decoder.cpp):
// smooth random motion as ahrs.Solution transfers (29-byte payload, no covariances: 5 frames,
// 36 frame payload bytes per sample; or all three covariances of 9: 13 frames, 90 bytes), from
// one node or interleaved from four, about 1% of the frames with a byte corrupted (the CRC
// rejects those transfers). Throughput in payload bytes (tail bytes included) and frames
// (tests/bench/decoders/can_decoder_bench.hpp). Run: build/tests/bench/dronecan_ahrs_bench
#include <benchmark/benchmark.h>

#include "can_decoder_bench.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"

namespace posefair::drivers {
namespace {

std::vector<CanFrame> make_frames(bool covariances, int nodes) {
  SyntheticMotionSpec spec;
  spec.samples = 20000;
  spec.sample_rate_hz = 200.0;
  spec.cycles = 20.0;
  spec.rotation_noise = 0.01;
  spec.with_position = false;
  const SyntheticMotion motion = make_synthetic_motion(spec);
  const std::uint8_t n = covariances ? 9 : 0;
  std::vector<std::vector<CanFrame>> transfers;
  for (std::size_t k = 0; k < motion.noisy.size(); ++k) {
    const auto payload = serialize_dronecan_ahrs_solution(motion.noisy.orientation[k], 5000 * (k + 1), {n, n, n});
    transfers.push_back(encode_dronecan_transfer(kDroneCanAhrsSolutionId, kDroneCanAhrsSolutionSignature, payload,
                                                 static_cast<std::uint8_t>(10 + k % static_cast<std::size_t>(nodes)),
                                                 static_cast<std::uint8_t>(k / static_cast<std::size_t>(nodes))));
  }
  std::vector<CanFrame> frames;
  for (std::size_t k = 0; k < transfers.size(); k += static_cast<std::size_t>(nodes)) {  // interleave `nodes` transfers
    const std::size_t end = std::min(transfers.size(), k + static_cast<std::size_t>(nodes));
    for (std::size_t i = 0; i < transfers[k].size(); ++i)
      for (std::size_t t = k; t < end; ++t)
        if (i < transfers[t].size()) frames.push_back(transfers[t][i]);
  }
  std::mt19937_64 rng(1);
  bench::corrupt_frames(frames, 0.01, rng);
  return frames;
}

void BM_DroneCanAhrsDecode(benchmark::State& state) {
  const std::vector<CanFrame> frames = make_frames(state.range(0) != 0, static_cast<int>(state.range(1)));
  auto decoder = make_dronecan_ahrs_decoder();
  bench::decode_frames(state, *decoder, frames);
}
BENCHMARK(BM_DroneCanAhrsDecode)->Args({0, 1})->Args({1, 1})->Args({0, 4})->ArgNames({"covariances", "nodes"});

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
