#pragma once
// Random CAN frames for tests (the CAN decoder tests and the candump log tests). No test
// framework behind it; the frame is formats' plain value, so it needs no drivers code.
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "posefair/formats/can_frame.hpp"

namespace posefair::testing {

// `count` frames with identifiers drawn from `ids` (can_id values), random classic lengths
// 0..8 and random payload bytes, timestamps 1 ms apart.
inline std::vector<formats::CanFrame> random_frames(std::size_t count, const std::vector<std::uint32_t>& ids, std::mt19937_64& rng) {
  std::vector<formats::CanFrame> frames(count);
  std::uniform_int_distribution<std::size_t> pick(0, ids.size() - 1);
  for (std::size_t k = 0; k < count; ++k) {
    formats::CanFrame& f = frames[k];
    f.can_id = ids[pick(rng)];
    f.len = static_cast<std::uint8_t>(rng() % 9);
    const std::uint64_t r = rng();
    for (std::size_t b = 0; b < 8; ++b) f.data[b] = static_cast<std::uint8_t>(r >> (8 * b));
    f.timestamp = 1e-3 * static_cast<double>(k);
  }
  return frames;
}

}  // namespace posefair::testing
