#pragma once
// What every CAN decoder fuzz target checks. The input is turned into frames
// (frames_from_bytes in tests/support/can_decoder_feed.hpp: identifiers mostly drawn from the
// decoder's own, some raw ids with any flags, classic and FD lengths, timestamps that jump) and
// fed to a fresh decoder; then fed again with an error frame and a foreign frame before each
// frame, which must change neither the samples nor the counters. Every frame is counted once,
// every payload byte of a frame it reads is counted, every sample is a finite unit quaternion
// with finite time and position. abort() otherwise.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

#include "../support/can_decoder_feed.hpp"

namespace posefair::testing {

using MakeCanDecoder = std::unique_ptr<drivers::CanDecoder> (*)(const posefair::OptionMap&);

inline CanDecoded fuzz_can_decoder(MakeCanDecoder make, const posefair::OptionMap& options,
                                   std::span<const std::uint8_t> data, std::span<const std::uint32_t> ids,
                                   std::uint32_t foreign_id) {
  const std::vector<drivers::CanFrame> frames = frames_from_bytes(data, ids);
  CanDecoded whole = decode_frames(make(options), frames);
  const drivers::CanFrameCounters& fc = whole.frame_counters;
  if (whole.counters.samples != whole.samples.size() || fc.received != frames.size() ||
      fc.foreign + fc.remote + fc.errors > fc.received || whole.counters.samples > whole.counters.frames)
    std::abort();
  std::uint64_t addressed = 0;
  for (const auto& f : frames) addressed += f.len;
  if (whole.counters.bytes > addressed || whole.counters.skipped_bytes > whole.counters.bytes) std::abort();

  std::vector<drivers::CanFrame> mixed;
  for (const auto& f : frames) {
    drivers::CanFrame err = f;
    err.can_id = drivers::CanFrame::kErrFlag | 0x40;
    drivers::CanFrame other = f;
    other.can_id = foreign_id;
    mixed.push_back(err);
    mixed.push_back(other);
    mixed.push_back(f);
  }
  const CanDecoded with = decode_frames(make(options), mixed);
  if (!(with.counters == whole.counters) || with.samples.size() != whole.samples.size()) std::abort();
  for (std::size_t i = 0; i < whole.samples.size(); ++i)
    if (!same(with.samples[i], whole.samples[i])) std::abort();

  for (const auto& s : whole.samples)
    if (!finite_unit(s.orientation, 1e-12) || !std::isfinite(s.device_time) || !s.position.allFinite()) std::abort();
  return whole;
}

}  // namespace posefair::testing
