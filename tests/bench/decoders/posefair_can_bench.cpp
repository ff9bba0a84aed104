// Decoding throughput of posefair's CAN layout decoder (drivers/src/posefair_can_decoder.cpp):
// smooth random motion (core/synthetic_motion.hpp) sent as TIME, POSITION and QUATERNION
// frames (20 payload bytes per sample), or quaternion frames only, about 1% of the frames with
// a byte corrupted. Throughput in payload bytes and frames (tests/bench/decoders/can_decoder_bench.hpp).
// Run: build/tests/bench/posefair_can_bench
#include <benchmark/benchmark.h>

#include "can_decoder_bench.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"

namespace posefair::drivers {
namespace {

std::vector<CanFrame> make_frames(bool full) {
  SyntheticMotionSpec spec;
  spec.samples = 40000;
  spec.sample_rate_hz = 400.0;
  spec.cycles = 20.0;
  spec.rotation_noise = 0.01;
  spec.with_position = true;
  const SyntheticMotion motion = make_synthetic_motion(spec);
  std::vector<CanFrame> frames;
  for (std::size_t k = 0; k < motion.noisy.size(); ++k) {
    const Vec3 p = motion.noisy.position[k] * 1e-3;  // mm -> m
    const auto f = encode_posefair_can(0x200, false, motion.noisy.orientation[k],
                                       full ? std::optional<std::uint32_t>(2500u * static_cast<std::uint32_t>(k)) : std::nullopt,
                                       full ? &p : nullptr, static_cast<std::uint8_t>(k));
    frames.insert(frames.end(), f.begin(), f.end());
  }
  std::mt19937_64 rng(1);
  bench::corrupt_frames(frames, 0.01, rng);
  return frames;
}

void BM_PosefairCanDecode(benchmark::State& state) {
  const std::vector<CanFrame> frames = make_frames(state.range(0) != 0);
  auto decoder = make_posefair_can_decoder();
  bench::decode_frames(state, *decoder, frames);
}
BENCHMARK(BM_PosefairCanDecode)->Arg(0)->Arg(1)->ArgName("time_and_position");

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
