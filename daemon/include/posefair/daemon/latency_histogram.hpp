#pragma once
// LatencyHistogram: durations in nanoseconds, recorded by any threads (lock-free, no
// allocation, relaxed/release atomic read-modify-writes) and read by any other thread as a
// HistogramSnapshot, a plain value that can be kept, compared and diffed.
//
// Buckets are log-linear (HdrHistogram style): 0..127 ns exact to the nanosecond, then every
// power of two [2^k, 2^(k+1)) split into 64 equal buckets, so a bucket is at most 1/64
// (1.6%) of its lower bound wide. Values from 2^34 ns (about 17.2 s) up go to one overflow
// bucket (and still count in max and mean). 1857 buckets, about 15 KB per histogram.
//
// A snapshot taken while recording runs is consistent enough for logs: each bucket is read
// atomically and only grows, so count and every percentile never go backwards between two
// snapshots taken by one thread; min, max and the sum are read after the buckets, so they
// cover every counted value (they may include a value recorded during the snapshot).
//
// There is no reset: to report an interval, keep the previous snapshot and take
// `now.since(previous)` (or `now - previous`).
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace posefair::daemon {

struct HistogramSnapshot {
  static constexpr int kSubBucketBits = 6;
  static constexpr std::uint64_t kSubBuckets = std::uint64_t{1} << kSubBucketBits;  // per octave
  static constexpr int kTopBits = 34;
  static constexpr std::uint64_t kTop = std::uint64_t{1} << kTopBits;  // >= kTop: overflow
  static constexpr std::size_t kOverflow = (kTopBits - kSubBucketBits + 1) * kSubBuckets;  // its index
  static constexpr std::size_t kBuckets = kOverflow + 1;  // including the overflow bucket

  std::uint64_t count = 0;
  std::uint64_t sum = 0;  // ns
  std::uint64_t min = 0;  // ns; 0 when count == 0
  std::uint64_t max = 0;  // ns; 0 when count == 0
  double mean = 0.0;      // ns; 0 when count == 0
  std::array<std::uint64_t, kBuckets> buckets{};

  std::uint64_t overflow_count() const { return buckets[kOverflow]; }

  // The p-th percentile (p in [0, 100]) by nearest rank: with rank = ceil(p/100 * count), the
  // inclusive upper bound of the bucket that holds the rank-th smallest value, capped at max
  // (so it is >= the true value and at most 1.6% above it; p = 100 gives max). p <= 0 gives
  // min; an empty snapshot gives 0. A rank in the overflow bucket gives max.
  std::uint64_t percentile(double p) const {
    if (count == 0) return 0;
    if (!(p > 0.0)) return min;
    if (p >= 100.0) return max;
    const double x = p / 100.0 * static_cast<double>(count);
    double r = std::ceil(x - x * 1e-12);  // 99.9% of 1000 is rank 999, not 1000
    r = std::clamp(r, 1.0, static_cast<double>(count));
    const auto rank = static_cast<std::uint64_t>(r);
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBuckets; ++i) {
      seen += buckets[i];
      if (seen >= rank) return i == kOverflow ? max : std::min(bucket_upper(i), max);
    }
    return max;  // unreachable while count == the sum of the buckets
  }

  // What was recorded after `earlier` (a snapshot of the same histogram taken before this
  // one). Counts, sum and mean are exact; min and max of the interval are not known exactly and
  // are taken from the outermost non-empty buckets (within 1.6%), clamped to this snapshot's
  // min and max (and max itself if the interval has overflowed values).
  HistogramSnapshot since(const HistogramSnapshot& earlier) const {
    HistogramSnapshot d;
    std::size_t first = kBuckets;
    std::size_t last = 0;
    for (std::size_t i = 0; i < kBuckets; ++i) {
      d.buckets[i] = buckets[i] > earlier.buckets[i] ? buckets[i] - earlier.buckets[i] : 0;
      if (d.buckets[i] == 0) continue;
      d.count += d.buckets[i];
      if (first == kBuckets) first = i;
      last = i;
    }
    if (d.count == 0) return d;
    d.sum = sum > earlier.sum ? sum - earlier.sum : 0;
    d.mean = static_cast<double>(d.sum) / static_cast<double>(d.count);
    d.min = std::max(bucket_lower(first), min);
    d.max = last == kOverflow ? max : std::min(bucket_upper(last), max);
    return d;
  }
  friend HistogramSnapshot operator-(const HistogramSnapshot& later, const HistogramSnapshot& earlier) {
    return later.since(earlier);
  }

  // The bucket of a value: v itself below 128; above, 64 buckets per power of two.
  static constexpr std::size_t bucket_of(std::uint64_t ns) {
    if (ns >= kTop) return kOverflow;
    const int width = std::bit_width(ns);
    const int shift = width > kSubBucketBits + 1 ? width - (kSubBucketBits + 1) : 0;
    return static_cast<std::size_t>(shift) * kSubBuckets + static_cast<std::size_t>(ns >> shift);
  }
  // The smallest value in bucket i.
  static constexpr std::uint64_t bucket_lower(std::size_t i) {
    if (i >= kOverflow) return kTop;
    if (i < 2 * kSubBuckets) return i;
    const std::size_t shift = i / kSubBuckets - 1;
    return static_cast<std::uint64_t>(i - shift * kSubBuckets) << shift;
  }
  // The largest value in bucket i (inclusive).
  static constexpr std::uint64_t bucket_upper(std::size_t i) {
    if (i >= kOverflow) return std::numeric_limits<std::uint64_t>::max();
    if (i < 2 * kSubBuckets) return i;
    const std::size_t shift = i / kSubBuckets - 1;
    return (static_cast<std::uint64_t>(i - shift * kSubBuckets + 1) << shift) - 1;
  }
};

class LatencyHistogram {
 public:
  LatencyHistogram() = default;
  LatencyHistogram(const LatencyHistogram&) = delete;
  LatencyHistogram& operator=(const LatencyHistogram&) = delete;

  // Any number of recording threads at once (each stream's engine role records the pipeline's
  // stage histograms): read-modify-write atomics, relaxed; min and max by compare-exchange, which
  // loops only while another thread moves them the same way.
  void record(std::uint64_t ns) noexcept {
    for (std::uint64_t m = min_.load(std::memory_order_relaxed); ns < m && !min_.compare_exchange_weak(m, ns, std::memory_order_relaxed);) {
    }
    for (std::uint64_t m = max_.load(std::memory_order_relaxed); ns > m && !max_.compare_exchange_weak(m, ns, std::memory_order_relaxed);) {
    }
    sum_.fetch_add(ns, std::memory_order_relaxed);
    // Release: a reader that sees this count also sees the min, max and sum above.
    buckets_[HistogramSnapshot::bucket_of(ns)].fetch_add(1, std::memory_order_release);
  }

  // Any thread, any time.
  HistogramSnapshot snapshot() const noexcept {
    HistogramSnapshot s;
    for (std::size_t i = 0; i < HistogramSnapshot::kBuckets; ++i) {
      s.buckets[i] = buckets_[i].load(std::memory_order_acquire);
      s.count += s.buckets[i];
    }
    if (s.count == 0) return s;
    s.sum = sum_.load(std::memory_order_relaxed);
    s.min = min_.load(std::memory_order_relaxed);
    s.max = max_.load(std::memory_order_relaxed);
    s.mean = static_cast<double>(s.sum) / static_cast<double>(s.count);
    return s;
  }

 private:
  std::array<std::atomic<std::uint64_t>, HistogramSnapshot::kBuckets> buckets_{};
  std::atomic<std::uint64_t> sum_{0};
  std::atomic<std::uint64_t> min_{std::numeric_limits<std::uint64_t>::max()};
  std::atomic<std::uint64_t> max_{0};
};

}  // namespace posefair::daemon
