#pragma once
// What the CAN decoder throughput benchmarks share. Throughput is counted in frame payload
// bytes (the 0..8 data bytes of each classic frame, DroneCAN's tail byte included; the
// identifier, DLC and the bus's own framing are not counted) and in frames: bytes_per_second
// and items_per_second. At 1 Mbit/s, the fastest classic bus, a fully loaded bus carries about
// 8.5k-17k frames/s, i.e. at most ~0.14 MB/s of payload; the goal of 50 MB/s is the serial
// decoders' and leaves a factor of several hundred.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "posefair/drivers/can_decoder.hpp"

namespace posefair::bench {

// Replaces, with probability `fraction` per frame, one payload byte by a random one.
inline void corrupt_frames(std::vector<drivers::CanFrame>& frames, double fraction, std::mt19937_64& rng) {
  std::bernoulli_distribution hit(fraction);
  for (auto& f : frames)
    if (hit(rng) && f.len > 0) f.data[rng() % f.len] = static_cast<std::uint8_t>(rng());
}

struct CountingCanSink final : drivers::DecodedSink {
  std::uint64_t samples = 0;
  double sum = 0.0;
  void on_sample(const drivers::DecodedSample& s) override {
    ++samples;
    sum += s.orientation.w();
  }
};

// Every iteration feeds all of `frames` to `decoder`. Reports payload bytes/s, frames/s and
// samples per pass.
inline void decode_frames(benchmark::State& state, drivers::CanDecoder& decoder, const std::vector<drivers::CanFrame>& frames) {
  CountingCanSink sink;
  std::uint64_t bytes = 0;
  for (const auto& f : frames) bytes += f.len;
  for (auto _ : state) {
    for (const auto& f : frames) decoder.feed(f, sink);
    benchmark::DoNotOptimize(sink.sum);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(bytes));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(frames.size()));
  state.counters["frames_per_pass"] = static_cast<double>(frames.size());
  state.counters["samples_per_pass"] = static_cast<double>(decoder.counters().samples) / static_cast<double>(state.iterations());
}

}  // namespace posefair::bench
