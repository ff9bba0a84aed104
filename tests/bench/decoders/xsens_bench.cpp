// Decoding throughput of the Xsens MTData2 decoder (drivers/src/xsens_decoder.cpp): MB/s of a
// realistic stream, MTData2 messages with PacketCounter, SampleTimeFine and a float32
// quaternion (36 bytes each) along smooth random motion (core/synthetic_motion.hpp), with
// about 1% of the bytes replaced by random ones. Fed in pieces of 64 bytes (what a serial read
// typically returns) or 4096. Goal: at least 50 MB/s on one core.
// Run: build/tests/bench/xsens_bench
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "decoder_bench.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/drivers/xsens_decoder.hpp"

namespace posefair::drivers {
namespace {

std::vector<std::uint8_t> make_stream() {
  SyntheticMotionSpec spec;
  spec.samples = 40000;
  spec.sample_rate_hz = 400.0;
  spec.cycles = 20.0;
  spec.rotation_noise = 0.01;
  spec.with_position = false;
  const SyntheticMotion motion = make_synthetic_motion(spec);
  std::vector<std::uint8_t> stream;
  for (std::size_t k = 0; k < motion.noisy.size(); ++k) {
    const std::vector<std::uint8_t> m = encode_xsens_mtdata2(
        motion.noisy.orientation[k], static_cast<std::uint16_t>(k), static_cast<std::uint32_t>(25 * k));
    stream.insert(stream.end(), m.begin(), m.end());
  }
  std::mt19937_64 rng(1);
  bench::corrupt(stream, 0.01, rng);
  return stream;
}

void BM_XsensDecode(benchmark::State& state) {
  static const std::vector<std::uint8_t> stream = make_stream();
  auto decoder = make_xsens_decoder();
  bench::decode_in_reads(state, *decoder, stream, static_cast<std::size_t>(state.range(0)));
}
BENCHMARK(BM_XsensDecode)->Arg(64)->Arg(4096);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
