#pragma once
// What the CAN decoder unit tests share, with gtest expectations: comparing runs, random frames
// with the decoder's own identifiers, and the decoder-independent checks every CAN decoder must
// pass (frames it does not read are counted and change nothing).
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "can_decoder_feed.hpp"
#include "decoder_testing.hpp"
#include "random_can_frames.hpp"

namespace posefair::testing {

inline void expect_same(const CanDecoded& a, const CanDecoded& b, const std::string& what = "") {
  EXPECT_EQ(a.counters, b.counters) << what;
  EXPECT_EQ(a.frame_counters, b.frame_counters) << what;
  ASSERT_EQ(a.samples.size(), b.samples.size()) << what;
  for (std::size_t i = 0; i < a.samples.size(); ++i) EXPECT_TRUE(same(a.samples[i], b.samples[i])) << what << " sample " << i;
}

// random_frames(count, ids, rng): random_can_frames.hpp.

// Sum of the payload lengths.
inline std::uint64_t payload_bytes(const std::vector<drivers::CanFrame>& frames) {
  std::uint64_t n = 0;
  for (const auto& f : frames) n += f.len;
  return n;
}

// Error frames, remote frames and data frames with identifiers the decoder does not read
// (`foreign`) are counted as such and change neither the samples nor the decoder's counters:
// the stream decodes as it does without them.
inline void expect_other_frames_change_nothing(drivers::CanDecoder& with, drivers::CanDecoder& without,
                                               const std::vector<drivers::CanFrame>& stream,
                                               const std::vector<std::uint32_t>& foreign_ids) {
  std::vector<drivers::CanFrame> mixed;
  std::uint64_t errors = 0, remotes = 0, foreign = 0;
  for (std::size_t k = 0; k < stream.size(); ++k) {
    const drivers::CanFrame& f = stream[k];
    drivers::CanFrame err = f;
    err.can_id = drivers::CanFrame::kErrFlag | 0x004;
    drivers::CanFrame rtr = f;
    rtr.can_id |= drivers::CanFrame::kRtrFlag;
    drivers::CanFrame other = f;
    other.can_id = foreign_ids[k % foreign_ids.size()];
    mixed.push_back(err);
    mixed.push_back(other);
    mixed.push_back(f);
    mixed.push_back(rtr);
    ++errors, ++remotes, ++foreign;
  }
  const CanDecoded a = decode_frames(without, stream);
  const CanDecoded b = decode_frames(with, mixed);
  EXPECT_EQ(a.counters, b.counters);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) EXPECT_TRUE(same(a.samples[i], b.samples[i])) << i;
  EXPECT_EQ(b.frame_counters.received, mixed.size());
  EXPECT_EQ(b.frame_counters.errors, errors);
  EXPECT_EQ(b.frame_counters.remote, remotes);
  EXPECT_EQ(b.frame_counters.foreign, foreign);
}

// Every filter passes every frame of `frames`, and one filter of the list refuses each of
// `refused` (can_id values).
inline void expect_filters_pass(const std::vector<drivers::CanFilter>& filters, const std::vector<drivers::CanFrame>& frames,
                                const std::vector<std::uint32_t>& refused) {
  for (const auto& f : frames) {
    bool any = false;
    for (const auto& flt : filters) any = any || flt.matches(f.can_id);
    EXPECT_TRUE(any) << std::hex << f.can_id;
  }
  for (const std::uint32_t id : refused) {
    bool any = false;
    for (const auto& flt : filters) any = any || flt.matches(id);
    EXPECT_FALSE(any) << std::hex << id;
  }
}

}  // namespace posefair::testing
