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

#include "posefair/drivers/bno08x_rvc_decoder.hpp"

namespace posefair::drivers {
namespace {

using Bytes = std::vector<std::uint8_t>;

struct CountingSink : DecodedSink {
  std::uint64_t n = 0;
  double sum = 0.0;
  void on_sample(const DecodedSample& s) override {
    ++n;
    sum += s.orientation.w();
  }
};

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
  std::uniform_int_distribution<std::size_t> at(0, s.size() - 1);
  for (std::size_t i = 0; i < static_cast<std::size_t>(corrupt_fraction * static_cast<double>(s.size())); ++i)
    s[at(rng)] = static_cast<std::uint8_t>(rng());
  return s;
}

void run(benchmark::State& state, const Bytes& stream) {
  const auto chunk = static_cast<std::size_t>(state.range(0));
  auto decoder = make_bno08x_rvc_decoder(DecoderOptions{});
  CountingSink sink;
  for (auto _ : state) {
    for (std::size_t at = 0; at < stream.size(); at += chunk)
      decoder->feed(std::span<const std::uint8_t>(stream.data() + at, std::min(chunk, stream.size() - at)), sink);
    benchmark::DoNotOptimize(sink.sum);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
  const auto& c = decoder->counters();
  state.counters["samples/MB"] = static_cast<double>(c.samples) / (static_cast<double>(c.bytes) / 1e6);
  state.counters["bad_sum%"] = 100.0 * static_cast<double>(c.bad_checksum) / static_cast<double>(c.bad_checksum + c.frames);
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
