// `posefair sub` accounting in process: lost, reordered, duplicates, latency, the stats line.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "protocol_samples.hpp"
#include "sub_command.hpp"

namespace posefair::tools {
namespace {

using V = SequenceTracker::Verdict;

TEST(SequenceTracker, CountsGapsAsLost) {
  SequenceTracker t;
  EXPECT_EQ(t.observe(10), V::kFirst);  // where we join is not a loss
  EXPECT_EQ(t.observe(11), V::kNext);
  EXPECT_EQ(t.observe(15), V::kAfterGap);
  EXPECT_EQ(t.lost(), 3u);
  EXPECT_EQ(t.received(), 3u);
  EXPECT_EQ(t.reordered(), 0u);
}

TEST(SequenceTracker, LateArrivalIsReorderedAndNoLongerLost) {
  SequenceTracker t;
  for (std::uint64_t s : {0, 1, 3, 4}) t.observe(s);
  EXPECT_EQ(t.lost(), 1u);
  EXPECT_EQ(t.observe(2), V::kReordered);
  EXPECT_EQ(t.lost(), 0u);
  EXPECT_EQ(t.reordered(), 1u);
  EXPECT_EQ(t.observe(2), V::kDuplicate);  // …and a second copy of it is a duplicate
  EXPECT_EQ(t.duplicates(), 1u);
  EXPECT_EQ(t.lost(), 0u);
}

TEST(SequenceTracker, RepeatsAreDuplicates) {
  SequenceTracker t;
  t.observe(5);
  EXPECT_EQ(t.observe(5), V::kDuplicate);
  t.observe(6);
  t.observe(7);
  EXPECT_EQ(t.observe(6), V::kDuplicate);
  EXPECT_EQ(t.duplicates(), 2u);
  EXPECT_EQ(t.reordered(), 0u);
  EXPECT_EQ(t.lost(), 0u);
  EXPECT_EQ(t.received(), 5u);
}

TEST(SequenceTracker, NumbersBeforeTheFirstSeenAreReorderedButWereNeverLost) {
  SequenceTracker t;
  t.observe(100);
  EXPECT_EQ(t.observe(99), V::kReordered);
  EXPECT_EQ(t.lost(), 0u);
  EXPECT_EQ(t.observe(99), V::kDuplicate);
}

TEST(SequenceTracker, HugeJumpsForgetTheWindowCleanly) {
  SequenceTracker t;
  t.observe(0);
  t.observe(1);
  EXPECT_EQ(t.observe(1'000'000), V::kAfterGap);
  EXPECT_EQ(t.lost(), 999'998u);
  // Slots that held 0 and 1 now stand for numbers near the new highest, none seen yet.
  EXPECT_EQ(t.observe(1'000'000 - SequenceTracker::kWindow + 1), V::kReordered);
  EXPECT_EQ(t.observe(999'999), V::kReordered);
  EXPECT_EQ(t.lost(), 999'996u);
  EXPECT_EQ(t.observe(std::numeric_limits<std::uint64_t>::max()), V::kAfterGap);
}

TEST(LatencyStats, MinMedianP99Max) {
  LatencyStats l;
  EXPECT_TRUE(std::isnan(l.quantile(0.5)));
  for (int i = 100; i >= 1; --i) l.add(i * 1e-6);
  EXPECT_EQ(l.count(), 100u);
  EXPECT_DOUBLE_EQ(l.min(), 1e-6);
  EXPECT_DOUBLE_EQ(l.max(), 100e-6);
  EXPECT_DOUBLE_EQ(l.quantile(0.5), 50e-6);
  EXPECT_DOUBLE_EQ(l.quantile(0.99), 99e-6);
}

TEST(SubscriberStats, SummaryLineNamesEveryCountAndReason) {
  SubscriberStats s;
  const auto now = std::chrono::system_clock::now();
  const double now_s = std::chrono::duration<double>(now.time_since_epoch()).count();
  for (std::uint64_t seq : {0, 1, 2, 4, 3, 3}) {
    auto m = daemon::testing::sample_message(0, seq);
    m.send_time = now_s - 250e-6;
    s.observe(m, now);
  }
  auto other = daemon::testing::sample_message(0, 7, /*session=*/9, /*stream=*/1);
  other.send_time = 0;  // not set: no latency sample
  s.observe(other, now);
  s.reject(daemon::DecodeError::kBadMagic);
  s.reject(daemon::DecodeError::kBadMagic);
  s.reject(daemon::DecodeError::kOversized);
  const std::string line = s.summary_line();
  EXPECT_EQ(line.rfind("stats: received 7, lost 0, reordered 1, duplicates 1, malformed 3 (oversized 1, bad-magic 2), "
                       "latency min 2",
                       0),
            0u)
      << line;
  EXPECT_NE(line.find("p50 250 µs"), std::string::npos) << line;
  EXPECT_EQ(s.streams.size(), 2u);
  ASSERT_EQ(s.stream_lines().size(), 2u);
  EXPECT_NE(s.stream_lines()[0].find("received 1"), std::string::npos) << s.stream_lines()[0];

  SubscriberStats empty;
  EXPECT_EQ(empty.summary_line(), "stats: received 0, lost 0, reordered 0, duplicates 0, malformed 0, latency n/a");
}

}  // namespace
}  // namespace posefair::tools
