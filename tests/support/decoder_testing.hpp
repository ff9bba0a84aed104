#pragma once
// What the protocol decoder unit tests (tests/drivers/decoders/) share: feeding a stream in
// given chunks and comparing runs (decoder_feed.hpp), with gtest expectations; the split checks
// (every two-way split, byte by byte, random chunkings); random bytes and the statistics their
// false accepts are held to; and a few builders of bytes and orientations.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "decoder_feed.hpp"
#include "hex_bytes.hpp"

namespace posefair::testing {

// A fresh decoder, the same every call.
using MakeTestDecoder = std::function<std::unique_ptr<drivers::Decoder>()>;

// The same counters and samples; `what` says which run `b` is.
inline void expect_same(const Decoded& a, const Decoded& b, const std::string& what = "") {
  EXPECT_EQ(a.counters, b.counters) << what;
  ASSERT_EQ(a.samples.size(), b.samples.size()) << what;
  for (std::size_t i = 0; i < a.samples.size(); ++i) EXPECT_TRUE(same(a.samples[i], b.samples[i])) << what << " sample " << i;
}

// `stream` cut in two at every offset 0 .. size gives what it gave whole. Stops at the first
// cut that does not.
inline void expect_every_split_same(const MakeTestDecoder& make, std::span<const std::uint8_t> stream, const Decoded& whole) {
  for (std::size_t cut = 0; cut <= stream.size(); ++cut) {
    const Decoded r = decode_chunks(make(), stream, {cut});
    if (!same(whole, r)) {
      expect_same(whole, r, "cut " + std::to_string(cut));
      return;
    }
  }
}

// `stream` fed one byte at a time gives what it gave whole.
inline void expect_byte_by_byte_same(const MakeTestDecoder& make, std::span<const std::uint8_t> stream, const Decoded& whole) {
  expect_same(whole, decode_chunks(make(), stream, std::vector<std::size_t>(stream.size(), 1)), "byte by byte");
}

// Chunk sizes drawn from `next` until they cover `total` bytes (decode_chunks cuts the last).
template <typename Next>
std::vector<std::size_t> random_chunks(std::size_t total, Next next) {
  std::vector<std::size_t> chunks;
  for (std::size_t at = 0; at < total; at += chunks.back()) chunks.push_back(next());
  return chunks;
}

// `stream` cut at random `trials` times gives what it gave whole each time. Trial t's chunks
// are 0 .. max_chunk[t % max_chunk.size()] bytes long (0: an empty feed), drawn from rng.
inline void expect_random_chunkings_same(const MakeTestDecoder& make, std::span<const std::uint8_t> stream,
                                         const Decoded& whole, std::mt19937_64& rng, int trials,
                                         std::initializer_list<std::size_t> max_chunk) {
  for (int trial = 0; trial < trials; ++trial) {
    std::uniform_int_distribution<std::size_t> length(0, max_chunk.begin()[static_cast<std::size_t>(trial) % max_chunk.size()]);
    expect_same(whole, decode_chunks(make(), stream, random_chunks(stream.size(), [&] { return length(rng); })),
                "trial " + std::to_string(trial));
  }
}

// `stream` cut into chunks of 1 .. max_chunk bytes gives what it gave whole: one random
// chunking for each seed.
inline void expect_seeded_chunkings_same(const MakeTestDecoder& make, std::span<const std::uint8_t> stream,
                                         const Decoded& whole, std::initializer_list<std::uint64_t> seeds,
                                         std::size_t max_chunk) {
  for (const std::uint64_t seed : seeds) {
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<std::size_t> length(1, max_chunk);
    expect_same(whole, decode_chunks(make(), stream, random_chunks(stream.size(), [&] { return length(rng); })),
                "seed " + std::to_string(seed));
  }
}

// `bytes` fed in reads of 1 .. 4096 bytes drawn from `rng`, as a serial port returns them.
inline Decoded decode_in_random_reads(std::unique_ptr<drivers::Decoder> decoder, std::span<const std::uint8_t> bytes,
                                      std::mt19937_64& rng) {
  std::uniform_int_distribution<std::size_t> length(1, 4096);
  return decode_chunks(std::move(decoder), bytes, random_chunks(bytes.size(), [&] { return length(rng); }));
}

// ---- random bytes and the statistics of what a decoder accepts in them ----

// n bytes, each the low byte of one draw of rng.
inline std::vector<std::uint8_t> random_bytes(std::size_t n, std::mt19937_64& rng) {
  std::vector<std::uint8_t> out(n);
  for (auto& b : out) b = static_cast<std::uint8_t>(rng());
  return out;
}

// How often `first` is directly followed by `second` (e.g. a two-byte frame start).
inline std::uint64_t count_pairs(std::span<const std::uint8_t> bytes, std::uint8_t first, std::uint8_t second) {
  std::uint64_t n = 0;
  for (std::size_t i = 1; i < bytes.size(); ++i) n += bytes[i - 1] == first && bytes[i] == second;
  return n;
}

// What a decoder made of 10 MB of random bytes (each one draw of rng) fed in reads of 4096
// bytes, and how many candidate frame starts they hold: places where `first` is directly
// followed by `second`.
struct RandomReads {
  Decoded decoded;
  std::uint64_t candidates = 0;
};

inline RandomReads decode_random_reads_of_4096(std::unique_ptr<drivers::Decoder> decoder, std::mt19937_64& rng,
                                               std::uint8_t first, std::uint8_t second) {
  constexpr std::size_t kRead = 4096;
  constexpr std::size_t kReads = (10'000'000 + kRead - 1) / kRead;
  const std::vector<std::uint8_t> data = random_bytes(kReads * kRead, rng);
  return {decode_chunks(std::move(decoder), data, std::vector<std::size_t>(kReads, kRead)), count_pairs(data, first, second)};
}

// A count that is close to Poisson with mean `mean` is at most 6 standard deviations above it
// (plus `slack`, for means so small that one more is no evidence).
inline void expect_poisson_at_most(std::uint64_t count, double mean, double slack = 0.0) {
  EXPECT_LE(static_cast<double>(count), mean + 6.0 * std::sqrt(mean) + slack) << count << " (mean " << mean << ")";
}

// ... and within 6 standard deviations of it.
inline void expect_poisson_near(std::uint64_t count, double mean) {
  EXPECT_NEAR(static_cast<double>(count), mean, 6.0 * std::sqrt(mean));
}

// A count of successes in `trials` tries of probability p is within 6 standard deviations of
// its mean (plus `slack`).
inline void expect_binomial_within(std::uint64_t count, double trials, double p, double slack = 0.0) {
  const double mean = trials * p;
  const double sd = std::sqrt(trials * p * (1 - p));
  EXPECT_LE(static_cast<double>(count), mean + 6 * sd + slack) << "mean " << mean;
  EXPECT_GE(static_cast<double>(count), mean - 6 * sd - slack) << "mean " << mean;
}

// Every sample a finite unit quaternion (to 1e-12). Stops at the first that is not.
inline void expect_unit_quaternions(const std::vector<drivers::DecodedSample>& samples) {
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Quat& q = samples[i].orientation;
    ASSERT_TRUE(q.coeffs().allFinite()) << "sample " << i;
    ASSERT_NEAR(q.norm(), 1.0, 1e-12) << "sample " << i;
  }
}

// ---- bytes and orientations ----

// hex("FF 7F 00"): hex_bytes.hpp.

// The parts one after the other.
inline std::vector<std::uint8_t> cat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// A rotation drawn uniformly.
inline Quat random_unit_quaternion(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
}

// R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees, built from Eigen alone (not the library's
// Euler code, which the decoders use).
inline Quat zyx(double yaw_deg, double pitch_deg, double roll_deg) {
  const double deg = std::numbers::pi / 180.0;
  return Quat(Eigen::AngleAxisd(yaw_deg * deg, Vec3::UnitZ())) * Quat(Eigen::AngleAxisd(pitch_deg * deg, Vec3::UnitY())) *
         Quat(Eigen::AngleAxisd(roll_deg * deg, Vec3::UnitX()));
}

}  // namespace posefair::testing
