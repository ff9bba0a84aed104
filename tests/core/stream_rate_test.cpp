// A stream's rate from its times: jittered times give the median interval, clumped ones (samples
// read together and stamped together) the count over the elapsed time.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/stream_rate.hpp"

namespace posefair {
namespace {

// Device sample times k / rate, stamped when a read every `read_period` s delivers them, the
// samples of one read 1 µs apart (a serial adapter's latency timer, a USB or BLE packet).
std::vector<double> clumped_times(double rate, double read_period, int n) {
  std::vector<double> t(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double sampled = k / rate;
    t[static_cast<std::size_t>(k)] = std::ceil(sampled / read_period + 1e-9) * read_period + 0.003;
    if (k > 0 && t[static_cast<std::size_t>(k)] <= t[static_cast<std::size_t>(k - 1)]) t[static_cast<std::size_t>(k)] = t[static_cast<std::size_t>(k - 1)] + 1e-6;
  }
  return t;
}

std::vector<double> intervals(const std::vector<double>& t) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < t.size(); ++i) dt.push_back(t[i] - t[i - 1]);
  return dt;
}

TEST(StreamRate, JitteredTimesGiveTheMedianInterval) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(-0.003, 0.003);  // ±30 % of 10 ms
  std::vector<double> t;
  for (int k = 0; k < 500; ++k)
    if (k % 50 != 7) t.push_back(0.01 * k + jitter(rng));  // and a dropped sample now and then
  EXPECT_FALSE(intervals_are_clumped(intervals(t)));
  EXPECT_NEAR(sample_rate(t), 100.0, 3.0);

  StreamRateEstimate live;
  const auto dt = intervals(t);
  for (int i = 0; i < kRateIntervals - 1; ++i) live.note(dt[static_cast<std::size_t>(i)]);
  EXPECT_EQ(live.rate(), 0.0);
  live.note(dt[kRateIntervals - 1]);
  std::vector<double> first(dt.begin(), dt.begin() + kRateIntervals);
  std::sort(first.begin(), first.end());
  EXPECT_EQ(live.rate(), 1.0 / first[kRateIntervals / 2]);  // known after 8 intervals: their median
}

TEST(StreamRate, ClumpedTimesGiveTheCountOverTheElapsedTime) {
  struct Case {
    double rate, read_period;
  };
  for (const Case c : {Case{200.0, 0.015}, Case{1000.0, 0.016}, Case{100.0, 0.016}, Case{60.0, 0.0375}}) {
    SCOPED_TRACE(std::to_string(c.rate) + " Hz read every " + std::to_string(c.read_period) + " s");
    const auto t = clumped_times(c.rate, c.read_period, static_cast<int>(3 * c.rate));
    const auto dt = intervals(t);
    EXPECT_TRUE(intervals_are_clumped(dt));
    EXPECT_NEAR(sample_rate(t), c.rate, 0.01 * c.rate);  // the median interval would give 1 MHz

    StreamRateEstimate live;
    double elapsed = 0.0;
    for (const double d : dt) {
      live.note(d);
      elapsed += d;
      if (elapsed >= kClumpedRateSpan) continue;
      ASSERT_EQ(live.rate(), 0.0) << elapsed;
      if (elapsed > 0.1) {
        EXPECT_NEAR(live.typical_interval(), 1.0 / c.rate, 0.3 / c.rate) << elapsed;
      }
    }
    EXPECT_NEAR(live.rate(), c.rate, 0.03 * c.rate);
  }
}

TEST(StreamRate, PausesDoNotMakeARegularStreamLookClumped) {
  // 30 Hz frames, one in five delivered late by half a frame and the next on time, and a 2 s pause.
  std::vector<double> t;
  for (int k = 0; k < 300; ++k) t.push_back(k / 30.0 + (k % 5 == 2 ? 0.016 : 0.0) + (k >= 150 ? 2.0 : 0.0));
  EXPECT_FALSE(intervals_are_clumped(intervals(t)));
  EXPECT_NEAR(sample_rate(t), 30.0, 0.01);
}

}  // namespace
}  // namespace posefair
