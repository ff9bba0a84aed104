// The time rule for live devices (time_base.hpp, docs/devices.md "Timestamps"): receive time
// without a device clock; a clean device clock delivered with jitter and in bursts keeps its own
// spacing on the receive clock's scale; a drift within the tolerance stays trusted and is
// tracked; a reset or a jump falls back to receive time, is counted, and trust comes back.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/drivers/time_base.hpp"

namespace posefair::drivers {
namespace {

// One simulated sample: when the device measured it (on the receive clock's scale, "truth"),
// its device time, and when the driver read it.
struct Simulated {
  double truth = 0.0;
  std::optional<double> device;
  double receive = 0.0;
};

struct Stream {
  double rate_hz = 100.0;
  double device_epoch = 5000.0;  // device time of the first sample
  double truth_epoch = 100.0;    // CLOCK_MONOTONIC of the first sample
  double drift = 0.0;            // receive seconds per device second − 1
  double min_latency = 0.002;
  double jitter = 0.006;         // latency uniform in [min_latency, min_latency + jitter]
  int burst = 4;                 // samples delivered together (one read): all at the last one's arrival
  unsigned seed = 7;
};

// n samples, device time continuing from `first_index`.
std::vector<Simulated> simulate(const Stream& st, std::size_t n, std::size_t first_index = 0) {
  std::mt19937 rng(st.seed);
  std::uniform_real_distribution<double> latency(st.min_latency, st.min_latency + st.jitter);
  std::vector<Simulated> out(n);
  const double period = 1.0 / st.rate_hz;
  for (std::size_t i = 0; i < n; ++i) {
    const double k = static_cast<double>(first_index + i);
    out[i].device = st.device_epoch + k * period;
    out[i].truth = st.truth_epoch + k * period * (1.0 + st.drift);
    out[i].receive = out[i].truth + latency(rng);
  }
  // Bursts: a read returns every sample that arrived before its last one.
  const std::size_t burst = static_cast<std::size_t>(std::max(st.burst, 1));
  for (std::size_t g = 0; g < n; g += burst) {
    const std::size_t end = std::min(n, g + burst);
    double at = 0.0;
    for (std::size_t i = g; i < end; ++i) at = std::max(at, out[i].receive);
    for (std::size_t i = g; i < end; ++i) out[i].receive = at;
  }
  for (std::size_t i = 1; i < n; ++i) out[i].receive = std::max(out[i].receive, out[i - 1].receive);
  return out;
}

std::vector<TimeStamp> run(TimeBase& tb, const std::vector<Simulated>& samples) {
  std::vector<TimeStamp> out;
  out.reserve(samples.size());
  for (const Simulated& s : samples) out.push_back(tb.update(s.receive, s.device));
  return out;
}

void expect_strictly_increasing(const std::vector<TimeStamp>& out) {
  for (std::size_t i = 1; i < out.size(); ++i) ASSERT_GT(out[i].time, out[i - 1].time) << "at " << i;
}

// Index of the first trusted output, or out.size().
std::size_t first_trusted(const std::vector<TimeStamp>& out, std::size_t from = 0) {
  for (std::size_t i = from; i < out.size(); ++i)
    if (out[i].device_trusted) return i;
  return out.size();
}

TEST(TimeBase, WithoutDeviceTimeTheTimeIsTheReceiveTime) {
  TimeBase tb;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> step(0.0, 0.02);
  double r = 42.0;
  for (int i = 0; i < 500; ++i) {
    r += step(rng) + 1e-4;
    const TimeStamp t = tb.update(r, std::nullopt);
    EXPECT_EQ(t.time, r);
    EXPECT_FALSE(t.device_trusted);
  }
  EXPECT_EQ(tb.counters().receive_samples, 500u);
  EXPECT_EQ(tb.counters().device_samples, 0u);
  EXPECT_EQ(tb.counters().nudged, 0u);
  EXPECT_FALSE(tb.trusted());
  EXPECT_TRUE(std::isnan(tb.offset()));
}

TEST(TimeBase, SamplesOfOneReadStayInOrderOneMicrosecondApart) {
  TimeBase tb;
  EXPECT_EQ(tb.update(10.0, std::nullopt).time, 10.0);
  EXPECT_DOUBLE_EQ(tb.update(10.0, std::nullopt).time, 10.0 + 1e-6);
  EXPECT_DOUBLE_EQ(tb.update(10.0, std::nullopt).time, 10.0 + 2e-6);
  EXPECT_EQ(tb.update(10.5, std::nullopt).time, 10.5);
  EXPECT_EQ(tb.counters().nudged, 2u);
}

TEST(TimeBase, ReceiveSourceIgnoresTheDeviceClock) {
  TimeBase tb(TimeSource::Receive);
  const std::vector<Simulated> in = simulate(Stream{}, 1000);
  const std::vector<TimeStamp> out = run(tb, in);
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_FALSE(out[i].device_trusted);
    EXPECT_GE(out[i].time, in[i].receive);
    EXPECT_LT(out[i].time, in[i].receive + 1e-5);  // only the in-order nudge of a burst
  }
  EXPECT_EQ(tb.counters().device_samples, 0u);
}

TEST(TimeBase, ACleanDeviceClockRemovesTheDeliveryJitter) {
  const Stream st;  // 100 Hz, latency 2..8 ms, bursts of 4
  const std::vector<Simulated> in = simulate(st, 3000);  // 30 s
  TimeBase tb;
  const std::vector<TimeStamp> out = run(tb, in);
  expect_strictly_increasing(out);

  // The input is jittery: receive spacing is far from 10 ms.
  double worst_input = 0.0;
  for (std::size_t i = 1; i < in.size(); ++i) worst_input = std::max(worst_input, std::abs(in[i].receive - in[i - 1].receive - 0.01));
  EXPECT_GT(worst_input, 0.008);

  // Trusted after the 2 s of qualification (20 samples and a passed rate check), and for good.
  const std::size_t trusted_at = first_trusted(out);
  ASSERT_LT(trusted_at, out.size());
  EXPECT_GE(trusted_at, 200u);
  EXPECT_LE(trusted_at, 260u);
  for (std::size_t i = trusted_at; i < out.size(); ++i) ASSERT_TRUE(out[i].device_trusted) << i;
  EXPECT_EQ(tb.counters().qualifications, 1u);
  EXPECT_EQ(tb.counters().fallbacks, 0u);
  EXPECT_EQ(tb.counters().rate_disagreements, 0u);
  // Before: receive times exactly (bursts nudged apart).
  for (std::size_t i = 0; i < trusted_at; ++i) EXPECT_NEAR(out[i].time, in[i].receive, 1e-5);

  // After the entry slew (5 s on): spacing is the device's, exactly for nearly every sample and
  // within the ±2 % slew bound for every one; the time sits the least latency behind the truth
  // and never after the receive time.
  std::size_t exact = 0, checked = 0;
  double late = 0.0;
  for (std::size_t i = 500; i < out.size(); ++i) {
    const double spacing = out[i].time - out[i - 1].time;
    EXPECT_NEAR(spacing, 0.01, 0.02 * 0.01 + 1e-9) << i;
    if (std::abs(spacing - 0.01) < 1e-9) ++exact;
    ++checked;
    EXPECT_GE(out[i].time - in[i].truth, st.min_latency - 1e-9) << i;
    EXPECT_LE(out[i].time - in[i].truth, st.min_latency + 0.001) << i;
    late = std::max(late, out[i].time - in[i].receive);
  }
  // A sample that lowers the envelope may be timed after its receive time while o slews down
  // to the new envelope: by no more than the envelope's step, a fraction of the jitter.
  EXPECT_LT(late, 0.001) << late;
  EXPECT_GE(static_cast<double>(exact), 0.95 * static_cast<double>(checked));
  EXPECT_NEAR(tb.offset(), st.truth_epoch - st.device_epoch + st.min_latency, 0.001);
}

TEST(TimeBase, TheEntryIntoTrustContinuesFromTheReceiveTimes) {
  const std::vector<Simulated> in = simulate(Stream{}, 600);
  TimeBase tb;
  const std::vector<TimeStamp> out = run(tb, in);
  const std::size_t at = first_trusted(out);
  ASSERT_LT(at, out.size());
  // The first trusted time is the previous time plus the device's step.
  EXPECT_NEAR(out[at].time - out[at - 1].time, 0.01, 1e-9);
  // Then it slews down to the envelope at no more than 2 %.
  for (std::size_t i = at + 1; i < out.size(); ++i) EXPECT_NEAR(out[i].time - out[i - 1].time, 0.01, 0.0002 + 1e-9);
}

class TimeBaseDrift : public ::testing::TestWithParam<double> {};

TEST_P(TimeBaseDrift, ADriftWithinTheToleranceStaysTrustedAndTheOffsetTracksIt) {
  Stream st;
  st.drift = GetParam();  // ±1 %
  const std::vector<Simulated> in = simulate(st, 6000);  // 60 s
  TimeBase tb;
  const std::vector<TimeStamp> out = run(tb, in);
  expect_strictly_increasing(out);
  const std::size_t at = first_trusted(out);
  ASSERT_LT(at, 300u);
  for (std::size_t i = at; i < out.size(); ++i) ASSERT_TRUE(out[i].device_trusted) << i;
  EXPECT_EQ(tb.counters().fallbacks, 0u);
  EXPECT_EQ(tb.counters().rate_disagreements, 0u);

  // Times are on the receive clock's scale: spacing is the device's times (1 + drift) on average.
  const double mean_spacing = (out.back().time - out[1000].time) / static_cast<double>(out.size() - 1 - 1000);
  EXPECT_NEAR(mean_spacing, 0.01 * (1.0 + st.drift), 1e-6);
  // The time stays within drift · window of the least-latency line (behind it when the device
  // runs slow: the envelope is up to a window old).
  const double lag_bound = std::abs(st.drift) * 2.0 * 1.05 + 0.002;
  for (std::size_t i = 1000; i < out.size(); ++i) {
    const double behind = in[i].truth + st.min_latency - out[i].time;
    EXPECT_LE(std::abs(behind), lag_bound) << i;
  }
  // The offset follows the drift: 50 s of device time later it moved by drift · 50 s.
  TimeBase probe;
  std::vector<Simulated> first(in.begin(), in.begin() + 1000);
  run(probe, first);
  EXPECT_NEAR(tb.offset() - probe.offset(), st.drift * 50.0, 0.025);
}

INSTANTIATE_TEST_SUITE_P(OnePercent, TimeBaseDrift, ::testing::Values(0.01, -0.01));

TEST(TimeBase, ADriftBeyondTheToleranceIsNeverTrusted) {
  for (const double drift : {0.05, -0.05}) {
    SCOPED_TRACE(drift);
    Stream st;
    st.drift = drift;
    const std::vector<Simulated> in = simulate(st, 3000);
    TimeBase tb;
    const std::vector<TimeStamp> out = run(tb, in);
    EXPECT_EQ(tb.counters().device_samples, 0u);
    EXPECT_GE(tb.counters().rate_disagreements, 5u);
    EXPECT_EQ(tb.counters().fallbacks, 0u);  // never trusted, so never fell back
    for (std::size_t i = 0; i < in.size(); ++i) EXPECT_NEAR(out[i].time, in[i].receive, 1e-5);
  }
}

TEST(TimeBase, ADeviceResetFallsBackIsCountedAndIsTrustedAgain) {
  const Stream st;
  std::vector<Simulated> in = simulate(st, 1000);  // 10 s
  // The device restarts: its clock starts again from 0, the samples keep coming.
  Stream after = st;
  after.device_epoch = 0.0;
  after.truth_epoch = in.back().truth + 0.01;
  after.seed = 11;
  const std::vector<Simulated> tail = simulate(after, 1000);
  in.insert(in.end(), tail.begin(), tail.end());
  for (std::size_t i = 1; i < in.size(); ++i) in[i].receive = std::max(in[i].receive, in[i - 1].receive);

  TimeBase tb;
  const std::vector<TimeStamp> out = run(tb, in);
  expect_strictly_increasing(out);
  EXPECT_EQ(tb.counters().went_back, 1u);
  EXPECT_EQ(tb.counters().fallbacks, 1u);
  EXPECT_EQ(tb.counters().qualifications, 2u);
  ASSERT_TRUE(out[999].device_trusted);
  EXPECT_FALSE(out[1000].device_trusted);
  EXPECT_NEAR(out[1000].time, in[1000].receive, 1e-5);
  const std::size_t again = first_trusted(out, 1000);
  ASSERT_LT(again, out.size());
  EXPECT_GE(again - 1000, 200u);  // 2 s of qualification
  EXPECT_LE(again - 1000, 260u);
  for (std::size_t i = again; i < out.size(); ++i) ASSERT_TRUE(out[i].device_trusted) << i;
  // Back on the least-latency line of the new clock.
  for (std::size_t i = again + 300; i < out.size(); ++i) {
    EXPECT_NEAR(out[i].time - in[i].truth, st.min_latency, 0.001) << i;
  }
  EXPECT_NEAR(tb.offset(), after.truth_epoch - after.device_epoch + st.min_latency, 0.001);
}

TEST(TimeBase, AJumpForwardFallsBack) {
  const Stream st;
  std::vector<Simulated> in = simulate(st, 1000);
  for (std::size_t i = 600; i < in.size(); ++i) *in[i].device += 10.0;  // a 10 s step in device time only
  TimeBase tb;
  const std::vector<TimeStamp> out = run(tb, in);
  expect_strictly_increasing(out);
  EXPECT_EQ(tb.counters().jumps, 1u);
  EXPECT_EQ(tb.counters().fallbacks, 1u);
  EXPECT_FALSE(out[600].device_trusted);
  EXPECT_TRUE(out.back().device_trusted);
}

TEST(TimeBase, ASmallLeapAheadOfTheDeviceClockFallsBackAtOnce) {
  const Stream st;
  std::vector<Simulated> in = simulate(st, 1500);
  for (std::size_t i = 600; i < in.size(); ++i) *in[i].device += 0.2;  // within max_step, but 200 ms off
  TimeBase tb;
  const std::vector<TimeStamp> out = run(tb, in);
  expect_strictly_increasing(out);
  EXPECT_EQ(tb.counters().jumps, 1u);
  EXPECT_EQ(tb.counters().rate_disagreements, 0u);
  EXPECT_EQ(tb.counters().fallbacks, 1u);
  EXPECT_TRUE(out[599].device_trusted);
  EXPECT_FALSE(out[600].device_trusted);
  EXPECT_NEAR(out[600].time, in[600].receive, 1e-5);
  EXPECT_TRUE(out.back().device_trusted);
}

TEST(TimeBase, DeviceSourceTrustsTheFirstSample) {
  Stream st;
  st.jitter = 0.0;
  st.burst = 1;
  const std::vector<Simulated> in = simulate(st, 300);
  TimeBase tb(TimeSource::Device);
  const std::vector<TimeStamp> out = run(tb, in);
  ASSERT_TRUE(out[0].device_trusted);
  EXPECT_NEAR(out[0].time, in[0].receive, 1e-9);
  for (std::size_t i = 1; i < out.size(); ++i) {
    EXPECT_TRUE(out[i].device_trusted);
    EXPECT_NEAR(out[i].time - out[i - 1].time, 0.01, 1e-9);
  }
  EXPECT_EQ(tb.counters().qualifications, 1u);
}

TEST(TimeBase, DeviceSourceReanchorsAfterAReset) {
  Stream st;
  st.jitter = 0.0;
  st.burst = 1;
  std::vector<Simulated> in = simulate(st, 200);
  for (std::size_t i = 100; i < in.size(); ++i) *in[i].device -= 5000.0;
  TimeBase tb(TimeSource::Device);
  const std::vector<TimeStamp> out = run(tb, in);
  expect_strictly_increasing(out);
  EXPECT_EQ(tb.counters().went_back, 1u);
  EXPECT_EQ(tb.counters().fallbacks, 0u);
  for (const TimeStamp& t : out) EXPECT_TRUE(t.device_trusted);
  EXPECT_NEAR(out[100].time, in[100].receive, 1e-9);
  EXPECT_NEAR(out[150].time - out[149].time, 0.01, 1e-9);
}

TEST(TimeBase, RestartAfterAReconnectRequalifiesWithoutAFallback) {
  const Stream st;
  std::vector<Simulated> in = simulate(st, 2000);
  TimeBase tb;
  std::vector<TimeStamp> out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (i == 1000) tb.restart();
    out.push_back(tb.update(in[i].receive, in[i].device));
  }
  expect_strictly_increasing(out);
  EXPECT_EQ(tb.counters().fallbacks, 0u);
  EXPECT_EQ(tb.counters().qualifications, 2u);
  EXPECT_FALSE(out[1000].device_trusted);
  EXPECT_TRUE(out.back().device_trusted);
}

TEST(TimeBase, BadOptionsAreRefused) {
  auto with = [](auto change) {
    TimeBaseOptions o;
    change(o);
    return o;
  };
  EXPECT_THROW(TimeBase(TimeSource::Auto, with([](TimeBaseOptions& o) { o.rate_tolerance = 0.0; })), std::invalid_argument);
  EXPECT_THROW(TimeBase(TimeSource::Auto, with([](TimeBaseOptions& o) { o.window = -1.0; })), std::invalid_argument);
  EXPECT_THROW(TimeBase(TimeSource::Auto, with([](TimeBaseOptions& o) { o.max_step = 0.0; })), std::invalid_argument);
  EXPECT_THROW(TimeBase(TimeSource::Auto, with([](TimeBaseOptions& o) { o.min_step = 0.0; })), std::invalid_argument);
  EXPECT_EQ(parse_time_source("auto"), TimeSource::Auto);
  EXPECT_EQ(parse_time_source("device"), TimeSource::Device);
  EXPECT_EQ(parse_time_source("receive"), TimeSource::Receive);
  EXPECT_EQ(parse_time_source("Auto"), std::nullopt);
}

}  // namespace
}  // namespace posefair::drivers
