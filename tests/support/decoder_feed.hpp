#pragma once
// Feeding a device protocol decoder (drivers/include/posefair/drivers/decoder.hpp) in tests,
// without a test framework, so that the fuzz targets (tests/fuzz/decoder_fuzz.hpp) use it as
// well as the unit tests (decoder_testing.hpp adds the gtest expectations): a sink that keeps
// every sample, what one run made of a stream, feeding a stream in given chunks, and comparing
// two runs.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "posefair/drivers/decoder.hpp"

namespace posefair::testing {

// Keeps every sample handed to it.
struct Collector final : drivers::DecodedSink {
  std::vector<drivers::DecodedSample> samples;
  void on_sample(const drivers::DecodedSample& s) override { samples.push_back(s); }
};

// What one decoder made of a stream: its samples, in order, and its counters at the end.
struct Decoded {
  std::vector<drivers::DecodedSample> samples;
  drivers::DecoderCounters counters;
};

// Feeds `bytes` to `decoder` in chunks of the given sizes, in order (each cut to what is left;
// a size of 0 feeds an empty span), then whatever is left as one last chunk (fed even when it
// is empty).
inline Decoded decode_chunks(std::unique_ptr<drivers::Decoder> decoder, std::span<const std::uint8_t> bytes,
                             const std::vector<std::size_t>& chunks = {}) {
  Collector sink;
  std::size_t at = 0;
  for (const std::size_t c : chunks) {
    const std::size_t n = std::min(c, bytes.size() - at);
    decoder->feed(bytes.subspan(at, n), sink);
    at += n;
  }
  decoder->feed(bytes.subspan(at), sink);
  return {std::move(sink.samples), decoder->counters()};
}

// The chunk sizes that cut a stream at the given offsets (increasing): {3, 7} gives {3, 4},
// and decode_chunks feeds the rest after offset 7.
inline std::vector<std::size_t> chunks_cut_at(const std::vector<std::size_t>& cuts) {
  std::vector<std::size_t> chunks;
  std::size_t start = 0;
  for (const std::size_t c : cuts) {
    chunks.push_back(c - start);
    start = c;
  }
  return chunks;
}

// Every field of the two samples equal, bit for bit.
inline bool same(const drivers::DecodedSample& a, const drivers::DecodedSample& b) {
  return a.orientation.coeffs() == b.orientation.coeffs() && a.position == b.position && a.gyro == b.gyro &&
         a.accel == b.accel && a.mag == b.mag && a.flags == b.flags && a.device_time == b.device_time && a.frame_counter == b.frame_counter &&
         a.has_frame_counter == b.has_frame_counter;
}

// The same counters and the same samples (every field, bit for bit).
inline bool same(const Decoded& a, const Decoded& b) {
  return a.counters == b.counters &&
         std::equal(a.samples.begin(), a.samples.end(), b.samples.begin(), b.samples.end(),
                    [](const drivers::DecodedSample& x, const drivers::DecodedSample& y) { return same(x, y); });
}

// A finite quaternion whose norm is within `tolerance` of 1.
inline bool finite_unit(const Quat& q, double tolerance) {
  return q.coeffs().allFinite() && std::abs(q.norm() - 1.0) <= tolerance;
}

}  // namespace posefair::testing
