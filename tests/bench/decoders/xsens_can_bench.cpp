// Decoding throughput of the Xsens MTi CAN decoder (drivers/src/xsens_can_decoder.cpp): smooth
// random motion as GroupCounter, SampleTime and Quaternion frames (14 payload bytes per
// sample), about 1% of the frames with a byte corrupted, among as many foreign frames (other
// MTi outputs: rate of turn 0x032, 6 bytes). Throughput in payload bytes and frames
// (tests/bench/decoders/can_decoder_bench.hpp). Run: build/tests/bench/xsens_can_bench
#include <benchmark/benchmark.h>

#include "can_decoder_bench.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"

namespace posefair::drivers {
namespace {

std::vector<CanFrame> make_frames(bool with_foreign) {
  SyntheticMotionSpec spec;
  spec.samples = 40000;
  spec.sample_rate_hz = 400.0;
  spec.cycles = 20.0;
  spec.rotation_noise = 0.01;
  spec.with_position = false;
  const SyntheticMotion motion = make_synthetic_motion(spec);
  std::vector<CanFrame> frames;
  const std::uint8_t rate[6] = {0x02, 0, 0, 0, 0, 0};
  for (std::size_t k = 0; k < motion.noisy.size(); ++k) {
    const auto f = encode_xsens_can(motion.noisy.orientation[k], 25u * static_cast<std::uint32_t>(k), static_cast<std::uint16_t>(k));
    frames.insert(frames.end(), f.begin(), f.end());
    if (with_foreign) frames.push_back(CanFrame::make(0x032, false, rate));
  }
  std::mt19937_64 rng(1);
  bench::corrupt_frames(frames, 0.01, rng);
  return frames;
}

void BM_XsensCanDecode(benchmark::State& state) {
  const std::vector<CanFrame> frames = make_frames(state.range(0) != 0);
  auto decoder = make_xsens_can_decoder();
  bench::decode_frames(state, *decoder, frames);
}
BENCHMARK(BM_XsensCanDecode)->Arg(0)->Arg(1)->ArgName("foreign");

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
