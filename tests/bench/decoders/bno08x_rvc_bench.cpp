// BNO08x UART-RVC decoder throughput (MB/s of input) on one core, over a realistic ~4 MB stream of
// 19-byte frames from a smooth synthetic motion, then 1% of the bytes replaced by random ones
// (Corrupted) or not (Clean). Every valid frame is a sample (three sin/cos pairs each).
// The argument is the size of each feed() call (a serial read returns tens to thousands of bytes).
// Run: build/tests/bench/bno08x_rvc_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "decoder_bench.hpp"
#include "posefair/drivers/bno08x_rvc_decoder.hpp"

namespace posefair::drivers {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes make_stream(double corrupt_fraction) {
  Bytes s;
  const int frames = 4'000'000 / 19;
  for (int k = 0; k < frames; ++k) {
    const double t = 0.01 * k;
    const auto f = encode_bno08x_rvc(static_cast<std::uint8_t>(k), 179.0 * std::sin(0.7 * t), 80.0 * std::sin(1.3 * t),
                                     170.0 * std::cos(0.9 * t), 300.0 * std::sin(t), -50.0, 980.0);
    s.insert(s.end(), f.begin(), f.end());
  }
  std::mt19937_64 rng(1);
  bench::corrupt(s, corrupt_fraction, rng);
  return s;
}

void run(benchmark::State& state, const Bytes& stream) {
  auto decoder = make_bno08x_rvc_decoder(OptionMap{});
  bench::decode_in_reads(state, *decoder, stream, static_cast<std::size_t>(state.range(0)));
}

void BM_Corrupted(benchmark::State& state) {
  static const Bytes stream = make_stream(0.01);
  run(state, stream);
}
void BM_Clean(benchmark::State& state) {
  static const Bytes stream = make_stream(0.0);
  run(state, stream);
}
BENCHMARK(BM_Corrupted)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Clean)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
