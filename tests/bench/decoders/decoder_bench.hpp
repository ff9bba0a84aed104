#pragma once
// What the decoder throughput benchmarks (tests/bench/decoders/) share: about 1% of a stream's
// bytes replaced by random ones, and the benchmark loop that feeds the whole stream to one
// decoder in reads of a given size and reports bytes/s. Each benchmark makes its own stream.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "posefair/drivers/decoder.hpp"

namespace posefair::bench {

// Replaces each byte, with probability `fraction`, by a random one; draws from rng for every
// byte (and once more for each byte replaced).
inline void corrupt(std::vector<std::uint8_t>& bytes, double fraction, std::mt19937_64& rng) {
  std::bernoulli_distribution hit(fraction);
  for (auto& b : bytes)
    if (hit(rng)) b = static_cast<std::uint8_t>(rng());
}

// Counts the samples and sums their w, so that the decoding cannot be optimised away.
struct CountingSink final : drivers::DecodedSink {
  std::uint64_t samples = 0;
  double sum = 0.0;
  void on_sample(const drivers::DecodedSample& s) override {
    ++samples;
    sum += s.orientation.w();
  }
};

// The benchmark loop: every iteration feeds all of `stream` to `decoder` in reads of `read_size`
// bytes (the last one shorter). Reports bytes/s, the stream's size, and from the decoder's
// counters the samples per pass and per MB of input and the share of whole frames whose
// checksum failed.
inline void decode_in_reads(benchmark::State& state, drivers::Decoder& decoder, const std::vector<std::uint8_t>& stream,
                            std::size_t read_size) {
  CountingSink sink;
  for (auto _ : state) {
    for (std::size_t at = 0; at < stream.size(); at += read_size)
      decoder.feed({stream.data() + at, std::min(read_size, stream.size() - at)}, sink);
    benchmark::DoNotOptimize(sink.sum);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(stream.size()));
  const drivers::DecoderCounters& c = decoder.counters();
  state.counters["stream_kB"] = static_cast<double>(stream.size()) / 1000.0;
  state.counters["samples_per_pass"] = static_cast<double>(c.samples) / static_cast<double>(state.iterations());
  state.counters["samples_per_MB"] = static_cast<double>(c.samples) / (static_cast<double>(c.bytes) / 1e6);
  state.counters["bad_checksum_pct"] = 100.0 * static_cast<double>(c.bad_checksum) / static_cast<double>(c.bad_checksum + c.frames);
}

}  // namespace posefair::bench
