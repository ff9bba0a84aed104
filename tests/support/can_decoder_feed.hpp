#pragma once
// Feeding a CAN decoder (drivers/include/posefair/drivers/can_decoder.hpp) in tests, without a
// test framework, so the fuzz targets use it as well as the unit tests: what one run made of a
// sequence of frames, comparing runs, and turning arbitrary bytes into frames (the fuzz input
// format, also used for the random-frame tests).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "decoder_feed.hpp"
#include "posefair/drivers/can_decoder.hpp"

namespace posefair::testing {

// What one CAN decoder made of a sequence of frames.
struct CanDecoded {
  std::vector<drivers::DecodedSample> samples;
  drivers::DecoderCounters counters;
  drivers::CanFrameCounters frame_counters;
};

inline CanDecoded decode_frames(drivers::CanDecoder& decoder, std::span<const drivers::CanFrame> frames) {
  Collector sink;
  for (const drivers::CanFrame& f : frames) decoder.feed(f, sink);
  return {std::move(sink.samples), decoder.counters(), decoder.frame_counters()};
}

inline CanDecoded decode_frames(std::unique_ptr<drivers::CanDecoder> decoder, std::span<const drivers::CanFrame> frames) {
  return decode_frames(*decoder, frames);
}

inline bool same(const CanDecoded& a, const CanDecoded& b) {
  return a.counters == b.counters && a.frame_counters == b.frame_counters &&
         std::equal(a.samples.begin(), a.samples.end(), b.samples.begin(), b.samples.end(),
                    [](const drivers::DecodedSample& x, const drivers::DecodedSample& y) { return same(x, y); });
}

// Bytes -> frames. Each frame is a header byte h, a length byte l, then its payload:
//   h & 3 < 3: the identifier is ids[(h >> 2) % ids.size()] (ids: can_id values with flags)
//   h & 3 == 3: the next 4 bytes (little-endian) are the whole can_id, flags included
//   h & 0x80 (and an id from the list): a CAN FD frame, length one of the 16 FD lengths by l
//   otherwise length l % 9
// the payload takes as many of the following bytes as the length asks for (fewer at the end);
// each frame's timestamp is the previous one plus ((h >> 4) & 7) · 0.4 s.
inline std::vector<drivers::CanFrame> frames_from_bytes(std::span<const std::uint8_t> in, std::span<const std::uint32_t> ids) {
  static constexpr std::array<std::uint8_t, 16> kFdLengths = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  std::vector<drivers::CanFrame> frames;
  std::size_t i = 0;
  double t = 0.0;
  while (i + 2 <= in.size()) {
    const std::uint8_t h = in[i++];
    drivers::CanFrame f;
    bool fd = false;
    if ((h & 3) < 3 && !ids.empty()) {
      f.can_id = ids[(h >> 2) % ids.size()];
      fd = (h & 0x80) != 0;
    } else {
      if (i + 4 > in.size()) break;
      f.can_id = static_cast<std::uint32_t>(in[i]) | static_cast<std::uint32_t>(in[i + 1]) << 8 |
                 static_cast<std::uint32_t>(in[i + 2]) << 16 | static_cast<std::uint32_t>(in[i + 3]) << 24;
      i += 4;
    }
    if (i >= in.size()) break;
    const std::uint8_t l = in[i++];
    std::size_t len = fd ? kFdLengths[l % 16] : l % 9;
    len = std::min(len, in.size() - i);
    f.fd = fd;
    f.len = static_cast<std::uint8_t>(len);
    std::copy_n(in.begin() + static_cast<std::ptrdiff_t>(i), len, f.data.begin());
    i += len;
    t += ((h >> 4) & 7) * 0.4;
    f.timestamp = t;
    frames.push_back(f);
  }
  return frames;
}

}  // namespace posefair::testing
