// LatencyHistogram: bucket layout, known distributions, the empty histogram, the overflow
// bucket, interval snapshots (differences), and a reader snapshotting while a writer records.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

#include "posefair/daemon/latency_histogram.hpp"

namespace posefair::daemon {
namespace {

using H = HistogramSnapshot;

// The nearest-rank percentile of sorted values, the definition percentile() approximates.
std::uint64_t exact_percentile(const std::vector<std::uint64_t>& sorted, double p) {
  const double x = p / 100.0 * static_cast<double>(sorted.size());
  auto rank = static_cast<std::size_t>(std::ceil(x - x * 1e-12));
  rank = std::clamp<std::size_t>(rank, 1, sorted.size());
  return sorted[rank - 1];
}

void expect_percentiles_close(const HistogramSnapshot& s, std::vector<std::uint64_t> values, double tolerance) {
  std::sort(values.begin(), values.end());
  for (double p : {0.0, 1.0, 10.0, 25.0, 50.0, 75.0, 90.0, 95.0, 99.0, 99.9, 99.99, 100.0}) {
    const std::uint64_t want = exact_percentile(values, p);
    const std::uint64_t got = s.percentile(p);
    EXPECT_GE(got, want) << "p" << p;  // an upper bound
    EXPECT_LE(static_cast<double>(got - want), tolerance * static_cast<double>(want)) << "p" << p;
  }
}

TEST(LatencyHistogram, BucketsTileTheRangeWithinOnePointSixPercent) {
  EXPECT_EQ(H::kBuckets, 1857u);
  for (std::size_t i = 0; i + 1 < H::kOverflow; ++i) {
    ASSERT_LE(H::bucket_lower(i), H::bucket_upper(i)) << i;
    ASSERT_EQ(H::bucket_upper(i) + 1, H::bucket_lower(i + 1)) << i;
    ASSERT_EQ(H::bucket_of(H::bucket_lower(i)), i);
    ASSERT_EQ(H::bucket_of(H::bucket_upper(i)), i);
    const double width = static_cast<double>(H::bucket_upper(i) - H::bucket_lower(i) + 1);
    if (i >= 128) {
      ASSERT_LE(width / static_cast<double>(H::bucket_lower(i)), 1.0 / 64.0) << i;
    } else {
      ASSERT_EQ(width, 1.0) << i;  // exact to the nanosecond below 128 ns
    }
  }
  EXPECT_EQ(H::bucket_lower(0), 0u);
  EXPECT_EQ(H::bucket_upper(H::kOverflow - 1), H::kTop - 1);
  EXPECT_EQ(H::bucket_of(H::kTop - 1), H::kOverflow - 1);
  EXPECT_EQ(H::bucket_of(H::kTop), H::kOverflow);
  EXPECT_EQ(H::bucket_of(std::numeric_limits<std::uint64_t>::max()), H::kOverflow);
  EXPECT_GT(H::kTop, 10'000'000'000u);  // 10 s fits below the overflow bucket
}

TEST(LatencyHistogram, EmptyHistogram) {
  LatencyHistogram h;
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.sum, 0u);
  EXPECT_EQ(s.min, 0u);
  EXPECT_EQ(s.max, 0u);
  EXPECT_EQ(s.mean, 0.0);
  EXPECT_EQ(s.overflow_count(), 0u);
  for (double p : {0.0, 50.0, 100.0}) EXPECT_EQ(s.percentile(p), 0u);
  const HistogramSnapshot d = s - s;
  EXPECT_EQ(d.count, 0u);
  EXPECT_EQ(d.percentile(99.0), 0u);
}

TEST(LatencyHistogram, OneValueIsEveryPercentile) {
  LatencyHistogram h;
  h.record(123'456);
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.count, 1u);
  EXPECT_EQ(s.min, 123'456u);
  EXPECT_EQ(s.max, 123'456u);
  EXPECT_EQ(s.mean, 123'456.0);
  for (double p : {0.0, 0.001, 50.0, 99.999, 100.0}) EXPECT_EQ(s.percentile(p), 123'456u) << p;
}

TEST(LatencyHistogram, UniformOneToThousandMicroseconds) {
  LatencyHistogram h;
  std::vector<std::uint64_t> values;
  for (std::uint64_t ns = 1'000; ns <= 1'000'000; ns += 7) values.push_back(ns);
  std::uint64_t sum = 0;
  for (std::uint64_t v : values) {
    h.record(v);
    sum += v;
  }
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.count, values.size());
  EXPECT_EQ(s.sum, sum);
  EXPECT_DOUBLE_EQ(s.mean, static_cast<double>(sum) / static_cast<double>(values.size()));
  EXPECT_EQ(s.min, 1'000u);
  EXPECT_EQ(s.max, values.back());
  EXPECT_EQ(s.overflow_count(), 0u);
  expect_percentiles_close(s, values, 0.03);
  // Within a tighter bound too: a bucket is at most 1/64 wide.
  expect_percentiles_close(s, values, 1.0 / 64.0);
  EXPECT_NEAR(static_cast<double>(s.percentile(50.0)), 500'000.0, 0.03 * 500'000.0);
  EXPECT_NEAR(static_cast<double>(s.percentile(99.0)), 990'000.0, 0.03 * 990'000.0);
}

TEST(LatencyHistogram, LogUniformFromHundredNanosecondsToTenSeconds) {
  LatencyHistogram h;
  std::vector<std::uint64_t> values;
  for (double x = 100.0; x <= 1e10; x *= 1.0007) values.push_back(static_cast<std::uint64_t>(x));
  for (std::uint64_t v : values) h.record(v);
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.overflow_count(), 0u);
  expect_percentiles_close(s, values, 1.0 / 64.0);
}

TEST(LatencyHistogram, OverflowBucketCountsInMaxAndMean) {
  LatencyHistogram h;
  for (int i = 0; i < 98; ++i) h.record(1'000'000);  // 1 ms
  h.record(20'000'000'000);  // 20 s
  h.record(30'000'000'000);  // 30 s
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.count, 100u);
  EXPECT_EQ(s.overflow_count(), 2u);
  EXPECT_EQ(s.max, 30'000'000'000u);
  EXPECT_EQ(s.min, 1'000'000u);
  EXPECT_DOUBLE_EQ(s.mean, (98.0 * 1e6 + 50e9) / 100.0);
  // Ranks among the 1 ms values: the upper bound of their bucket.
  EXPECT_EQ(s.percentile(50.0), H::bucket_upper(H::bucket_of(1'000'000)));
  EXPECT_EQ(s.percentile(98.0), H::bucket_upper(H::bucket_of(1'000'000)));
  EXPECT_LE(s.percentile(98.0), 1'000'000u + 1'000'000u / 64);
  EXPECT_EQ(s.percentile(99.0), 30'000'000'000u);  // rank in the overflow bucket: max
  EXPECT_EQ(s.percentile(100.0), 30'000'000'000u);
}

TEST(LatencyHistogram, SnapshotDifferenceIsTheLastInterval) {
  LatencyHistogram h;
  std::vector<std::uint64_t> first;
  std::vector<std::uint64_t> second;
  for (std::uint64_t i = 0; i < 5000; ++i) first.push_back(2'000 + i);           // ~2..7 µs
  for (std::uint64_t i = 0; i < 3000; ++i) second.push_back(400'000 + 97 * i);  // ~0.4..0.7 ms
  for (std::uint64_t v : first) h.record(v);
  const HistogramSnapshot a = h.snapshot();
  for (std::uint64_t v : second) h.record(v);
  const HistogramSnapshot b = h.snapshot();

  const HistogramSnapshot d = b - a;
  EXPECT_EQ(d.count, second.size());
  std::uint64_t sum = 0;
  for (std::uint64_t v : second) sum += v;
  EXPECT_EQ(d.sum, sum);
  EXPECT_DOUBLE_EQ(d.mean, static_cast<double>(sum) / static_cast<double>(second.size()));
  // min and max of an interval are bucket bounds around the true ones.
  EXPECT_LE(d.min, 400'000u);
  EXPECT_GE(static_cast<double>(d.min), 400'000.0 * (1.0 - 1.0 / 64.0));
  EXPECT_GE(d.max, second.back());
  EXPECT_LE(d.max, b.max);
  EXPECT_EQ(d.max, b.max);  // the interval holds the overall max: capped exactly
  for (double p : {1.0, 50.0, 90.0, 99.0}) {
    std::vector<std::uint64_t> sorted = second;
    const std::uint64_t want = exact_percentile(sorted, p);
    EXPECT_GE(d.percentile(p), want) << p;
    EXPECT_LE(static_cast<double>(d.percentile(p)), static_cast<double>(want) * 1.03) << p;
  }
  // The interval does not see the first batch; since-start does.
  EXPECT_GT(d.percentile(1.0), 100'000u);
  EXPECT_LT(b.percentile(50.0), 10'000u);
  EXPECT_EQ(b.since(a).count, d.count);
  EXPECT_EQ((b - b).count, 0u);
  EXPECT_EQ((a - HistogramSnapshot{}).count, a.count);  // since nothing: everything
  EXPECT_EQ((a - HistogramSnapshot{}).percentile(50.0), a.percentile(50.0));

  // An interval with an overflowed value reports the overall max.
  h.record(40'000'000'000);
  const HistogramSnapshot c = h.snapshot();
  const HistogramSnapshot e = c - b;
  EXPECT_EQ(e.count, 1u);
  EXPECT_EQ(e.overflow_count(), 1u);
  EXPECT_EQ(e.max, 40'000'000'000u);
  EXPECT_EQ(e.min, H::kTop);
  EXPECT_EQ(e.percentile(50.0), 40'000'000'000u);
}

TEST(LatencyHistogram, ZeroNanoseconds) {
  LatencyHistogram h;
  h.record(0);
  h.record(0);
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.count, 2u);
  EXPECT_EQ(s.min, 0u);
  EXPECT_EQ(s.max, 0u);
  EXPECT_EQ(s.percentile(50.0), 0u);
  EXPECT_EQ(s.buckets[0], 2u);
}

TEST(LatencyHistogram, SnapshotsWhileRecordingOnAnotherThread) {
  LatencyHistogram h;
  // The writer records at least kMinValues values and goes on until the reader has taken
  // kMinSnapshots snapshots, so the two surely overlap.
  constexpr std::uint64_t kMinValues = 200'000;
  constexpr std::uint64_t kMinSnapshots = 200;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> snapshots_taken{0};
  std::uint64_t recorded = 0;  // read after join
  std::thread writer([&] {
    std::uint64_t x = 88172645463325252ull;
    while (recorded < kMinValues || snapshots_taken.load(std::memory_order_relaxed) < kMinSnapshots) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      h.record(100 + x % 10'000'000);  // 100 ns .. 10 ms
      ++recorded;
    }
    done.store(true, std::memory_order_release);
  });

  std::uint64_t snapshots = 0;
  std::uint64_t last_count = 0;
  std::uint64_t last_p99 = 0;
  HistogramSnapshot previous;
  bool finished = false;
  while (!finished) {
    finished = done.load(std::memory_order_acquire);
    const HistogramSnapshot s = h.snapshot();
    snapshots_taken.store(++snapshots, std::memory_order_relaxed);
    std::uint64_t bucket_sum = 0;
    for (std::uint64_t b : s.buckets) bucket_sum += b;
    ASSERT_EQ(bucket_sum, s.count);
    ASSERT_GE(s.count, last_count);  // never goes backwards
    const HistogramSnapshot d = s - previous;
    ASSERT_EQ(d.count, s.count - last_count);
    if (s.count > 0) {
      ASSERT_LE(s.min, s.max);
      ASSERT_GE(s.min, 100u);
      ASSERT_LT(s.max, 10'000'100u);
      ASSERT_LE(s.percentile(50.0), s.percentile(99.0));
      ASSERT_LE(s.percentile(99.0), s.max);
      ASSERT_GE(s.percentile(0.0), 100u);
      ASSERT_GE(static_cast<double>(s.sum), static_cast<double>(s.count) * 100.0);  // sum covers every count
    }
    if (s.count >= 10'000) {  // p99 of a growing sample of one distribution stays put roughly
      if (last_p99 != 0) {
        ASSERT_NEAR(static_cast<double>(s.percentile(99.0)), static_cast<double>(last_p99), 0.1 * 1e7);
      }
      last_p99 = s.percentile(99.0);
    }
    last_count = s.count;
    previous = s;
  }
  writer.join();
  const HistogramSnapshot s = h.snapshot();
  EXPECT_EQ(s.count, recorded);
  EXPECT_EQ(last_count, recorded);  // the snapshot after `done` saw everything
  EXPECT_GE(snapshots, kMinSnapshots);
  EXPECT_NEAR(static_cast<double>(s.percentile(50.0)), 5e6, 0.03 * 5e6);
  EXPECT_NEAR(static_cast<double>(s.percentile(99.0)), 9.9e6, 0.03 * 9.9e6);
}

}  // namespace
}  // namespace posefair::daemon
