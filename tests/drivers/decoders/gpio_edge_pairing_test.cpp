// The GPIO edge pairing rule (drivers/include/posefair/drivers/gpio_edge_pairing.hpp): the
// tolerance window's bounds, missing edges, extra edges, jitter, edges arriving out of order
// and late, the pending limit, reset, and options out of range.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "posefair/drivers/gpio_edge_pairing.hpp"

namespace posefair::drivers::gpio_edge_pairing_test {
namespace {

EdgePairingOptions window(double lo, double hi) {
  EdgePairingOptions o;
  o.tolerance_min = lo;
  o.tolerance_max = hi;
  return o;
}

TEST(GpioEdgePairing, WindowBoundsAreInclusive) {
  // Binary fractions, so that r − tolerance is exact and the bounds are tested, not rounding.
  const double min = 1.0 / 1024, max = 1.0 / 256;
  EdgePairer p(window(min, max));
  p.add_edge(10.0);
  const PairedTime a = p.pair(10.0 + max);  // delay exactly tolerance_max
  EXPECT_TRUE(a.paired);
  EXPECT_EQ(a.time, 10.0);
  p.add_edge(10.0 + 1.0 / 64);
  const PairedTime b = p.pair(10.0 + 1.0 / 64 + min);  // exactly tolerance_min
  EXPECT_TRUE(b.paired);
  EXPECT_EQ(b.time, 10.0 + 1.0 / 64);
  p.add_edge(11.0);
  EXPECT_FALSE(p.pair(11.0 + max + 1.0 / 65536).paired);  // just past tolerance_max
  p.add_edge(12.0);
  EXPECT_FALSE(p.pair(12.0 + min - 1.0 / 65536).paired);  // just short of tolerance_min
  EXPECT_EQ(p.counters().paired, 2u);
  EXPECT_EQ(p.counters().missing, 2u);
}

TEST(GpioEdgePairing, EdgesOutsideTheWindowAreNotPaired) {
  EdgePairer p(window(0.001, 0.004));
  p.add_edge(10.000);
  const PairedTime early = p.pair(10.0005);  // the edge is too recent for this sample (delay < min)
  EXPECT_FALSE(early.paired);
  EXPECT_EQ(early.time, 10.0005);
  EXPECT_EQ(p.pending(), 1u);                 // kept for a later sample
  const PairedTime late = p.pair(10.0045);   // too old now: expired, counted as extra
  EXPECT_FALSE(late.paired);
  EXPECT_EQ(p.pending(), 0u);
  EXPECT_EQ(p.counters().missing, 2u);
  EXPECT_EQ(p.counters().extra_edges, 1u);
}

TEST(GpioEdgePairing, MissingEdgesKeepTheReceiveTime) {
  EdgePairer p(window(0.0, 0.002));
  int paired = 0;
  for (int k = 0; k < 100; ++k) {
    const double t = 1.0 + 0.01 * k;
    if (k % 10 != 3) p.add_edge(t);  // every tenth edge lost
    const PairedTime s = p.pair(t + 0.0015);
    if (k % 10 == 3) {
      EXPECT_FALSE(s.paired);
      EXPECT_EQ(s.time, t + 0.0015);
    } else {
      EXPECT_TRUE(s.paired);
      EXPECT_EQ(s.time, t);
      ++paired;
    }
  }
  EXPECT_EQ(p.counters().missing, 10u);
  EXPECT_EQ(p.counters().paired, 90u);
  EXPECT_EQ(p.counters().extra_edges, 0u);
}

TEST(GpioEdgePairing, ExtraEdgesAreCountedAndTheLatestIsPaired) {
  EdgePairer p(window(0.0, 0.005));
  p.add_edge(2.000);
  p.add_edge(2.001);  // a glitch: second edge in the same window
  const PairedTime s = p.pair(2.003);
  EXPECT_TRUE(s.paired);
  EXPECT_EQ(s.time, 2.001);
  EXPECT_EQ(p.counters().extra_edges, 1u);
  // Edges with no sample at all: expire as extra once no window can reach them.
  p.add_edge(2.010);
  p.add_edge(2.020);
  p.add_edge(2.030);
  const PairedTime t = p.pair(2.032);
  EXPECT_EQ(t.time, 2.030);
  EXPECT_EQ(p.counters().extra_edges, 3u);
  EXPECT_EQ(p.counters().edges, 5u);
  EXPECT_EQ(p.counters().paired, 2u);
}

TEST(GpioEdgePairing, JitteredDelaysWithinTheToleranceAllPair) {
  // 200 Hz data-ready, bytes received 0.2 .. 3 ms after the edge (USB, scheduler).
  EdgePairer p(window(0.0002, 0.003));
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> delay(0.0002, 0.003);
  std::normal_distribution<double> clock_jitter(0.0, 20e-6);
  for (int k = 0; k < 5000; ++k) {
    const double edge = 100.0 + 0.005 * k + clock_jitter(rng);
    p.add_edge(edge);
    const PairedTime s = p.pair(edge + delay(rng));
    ASSERT_TRUE(s.paired) << k;
    ASSERT_EQ(s.time, edge);
  }
  EXPECT_EQ(p.counters().paired, 5000u);
  EXPECT_EQ(p.counters().missing + p.counters().extra_edges + p.counters().late_edges, 0u);
}

TEST(GpioEdgePairing, DelaysBeyondTheToleranceAreMissingNotMispaired) {
  EdgePairer p(window(0.0, 0.002));
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> delay(0.0, 0.004);  // half of them too late
  int expected_missing = 0;
  for (int k = 0; k < 2000; ++k) {
    const double edge = 5.0 + 0.01 * k;
    const double d = delay(rng);
    p.add_edge(edge);
    const PairedTime s = p.pair(edge + d);
    if (d <= 0.002) {
      ASSERT_TRUE(s.paired);
      ASSERT_EQ(s.time, edge);
    } else {
      ASSERT_FALSE(s.paired);
      ++expected_missing;
    }
  }
  EXPECT_EQ(p.counters().missing, static_cast<std::uint64_t>(expected_missing));
  EXPECT_GT(expected_missing, 800);
}

TEST(GpioEdgePairing, EdgesAddedOutOfOrderAreSorted) {
  EdgePairer p(window(0.0, 0.004));
  // Three edges, 10 ms apart, delivered in reverse before their samples are paired.
  p.add_edge(3.020);
  p.add_edge(3.000);
  p.add_edge(3.010);
  EXPECT_EQ(p.pending(), 3u);
  EXPECT_EQ(p.pair(3.002).time, 3.000);
  EXPECT_EQ(p.pair(3.012).time, 3.010);
  EXPECT_EQ(p.pair(3.022).time, 3.020);
  EXPECT_EQ(p.counters().paired, 3u);
  EXPECT_EQ(p.counters().extra_edges, 0u);
}

TEST(GpioEdgePairing, AnEdgeAfterItsSampleIsLate) {
  EdgePairer p(window(0.0, 0.004));
  p.add_edge(4.000);
  EXPECT_TRUE(p.pair(4.001).paired);
  EXPECT_FALSE(p.pair(4.011).paired);  // its edge (4.010) not delivered yet: missing
  p.add_edge(4.010);                   // arrives afterwards: still pending, the next sample's window misses it
  p.add_edge(3.999);                   // older than the paired edge: late
  EXPECT_EQ(p.counters().late_edges, 1u);
  p.add_edge(4.020);
  const PairedTime s = p.pair(4.021);
  EXPECT_EQ(s.time, 4.020);
  EXPECT_EQ(p.counters().extra_edges, 1u);  // 4.010 expired
  p.add_edge(NAN);
  EXPECT_EQ(p.counters().late_edges, 2u);
}

TEST(GpioEdgePairing, OutOfOrderSamplesUseTheirOwnWindow) {
  EdgePairer p(window(0.0, 0.004));
  p.add_edge(6.000);
  p.add_edge(6.010);
  // The later sample is paired first; the earlier one then finds its edge gone (expired: older
  // than the latest sample's window) and keeps its receive time.
  EXPECT_EQ(p.pair(6.012).time, 6.010);
  const PairedTime early = p.pair(6.002);
  EXPECT_FALSE(early.paired);
  EXPECT_EQ(p.counters().extra_edges, 1u);
  EXPECT_EQ(p.counters().missing, 1u);
}

TEST(GpioEdgePairing, PendingLimitAndReset) {
  EdgePairer p(window(0.0, 1.0));
  for (int k = 0; k < 70; ++k) p.add_edge(1.0 + 0.001 * k);
  EXPECT_EQ(p.pending(), EdgePairer::kMaxPending);
  EXPECT_EQ(p.counters().overflow, 6u);
  p.reset();
  EXPECT_EQ(p.pending(), 0u);
  p.add_edge(0.5);  // before the last pairing would be late; after reset it is fine
  EXPECT_EQ(p.pair(0.6).time, 0.5);
  EXPECT_EQ(p.counters().edges, 71u);  // counters survive reset
}

TEST(GpioEdgePairing, OptionsOutOfRange) {
  EXPECT_THROW(EdgePairer(window(-0.001, 0.002)), std::invalid_argument);
  EXPECT_THROW(EdgePairer(window(0.003, 0.002)), std::invalid_argument);
  EXPECT_THROW(EdgePairer(window(0.0, INFINITY)), std::invalid_argument);
  EXPECT_THROW(EdgePairer(window(NAN, 0.002)), std::invalid_argument);
  EXPECT_NO_THROW(EdgePairer(window(0.002, 0.002)));
}

}  // namespace
}  // namespace posefair::drivers::gpio_edge_pairing_test
