// Gap bridging and output-rate resampling on the geometric spline (gap_bridge.hpp,
// fixed_rate_resampler.hpp): what the daemon relies on, on motion whose truth is known.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/fixed_rate_resampler.hpp"
#include "posefair/core/gap_bridge.hpp"

namespace posefair {
namespace {

// A smooth rotation (varying axis and rate) and a smooth path: the truth at any time.
Quat truth_q(double t) {
  const Vec3 r(0.8 * std::sin(1.3 * t), 0.5 * std::cos(0.7 * t), 0.3 * t);
  return so3::from_rotation_vector(r);
}
Vec3 truth_p(double t) { return Vec3(std::sin(t), 0.5 * t, std::cos(2.0 * t)); }

Sample sample_at(double t, std::uint64_t seq, bool position = true) {
  Sample s;
  s.stream_id = 3;
  s.sequence = seq;
  s.time = t;
  s.receive_time = t;
  s.orientation = truth_q(t);
  if (position) {
    s.position = truth_p(t);
    s.flags = kHasPosition;
  }
  return s;
}

FairedPose pose_at(double t, std::uint32_t flags = kHasPosition) {
  FairedPose p;
  p.stream_id = 3;
  p.time = t;
  p.orientation = truth_q(t);
  p.position = truth_p(t);
  p.flags = flags;
  return p;
}

TEST(GapBridge, ARegularStreamPassesThroughUnchanged) {
  GapBridge bridge(GapBridgeOptions{});
  std::vector<Sample> out(bridge.max_outputs());
  for (int i = 0; i < 200; ++i) {
    const Sample s = sample_at(0.01 * i, static_cast<std::uint64_t>(i));
    ASSERT_EQ(bridge.push(s, out), 1u) << i;
    EXPECT_EQ(out[0].time, s.time);
    EXPECT_EQ(out[0].sequence, s.sequence);
    EXPECT_EQ(out[0].flags, s.flags);
  }
  EXPECT_EQ(bridge.counters().gaps, 0u);
  EXPECT_EQ(bridge.flush(out), 0u);
}

TEST(GapBridge, AShortGapIsFilledOnTheSplineAtTheStreamsInterval) {
  GapBridge bridge(GapBridgeOptions{});
  std::vector<Sample> out(bridge.max_outputs());
  for (int i = 0; i <= 50; ++i) ASSERT_EQ(bridge.push(sample_at(0.01 * i, i), out), 1u);
  // Samples 51..56 are lost: 0.07 s between 0.50 and 0.57.
  EXPECT_EQ(bridge.push(sample_at(0.57, 57), out), 0u) << "the sample after the gap waits for its successor";
  const std::size_t n = bridge.push(sample_at(0.58, 58), out);
  ASSERT_EQ(n, 8u);  // 6 bridged, the held one, this one
  for (std::size_t j = 0; j < 6; ++j) {
    const Sample& b = out[j];
    EXPECT_NEAR(b.time, 0.51 + 0.01 * static_cast<double>(j), 1e-12);
    EXPECT_EQ(b.flags, kBridged | kHasPosition);
    EXPECT_LT(so3::rotation_angle(b.orientation, truth_q(b.time)), 2e-4) << "t = " << b.time;
    EXPECT_LT((b.position - truth_p(b.time)).norm(), 2e-4) << "t = " << b.time;
    EXPECT_NEAR(b.orientation.norm(), 1.0, 1e-12);
  }
  EXPECT_EQ(out[6].sequence, 57u);
  EXPECT_EQ(out[6].flags, kHasPosition);
  EXPECT_EQ(out[7].sequence, 58u);
  EXPECT_EQ(bridge.counters().gaps, 1u);
  EXPECT_EQ(bridge.counters().samples, 6u);
  // And the stream goes on regularly.
  EXPECT_EQ(bridge.push(sample_at(0.59, 59), out), 1u);
}

TEST(GapBridge, SamplesReadInClumpsPassThroughAndTheirGapsAreBridgedAtTheReadsPeriod) {
  // 250 Hz read every 16 ms: four samples a read, stamped 1 µs apart. The pause after a read is
  // no gap (by the last step, 1 µs, it was one of 16 000 missing samples, and 256 were made on
  // a spline through knots 1 µs apart). Three reads are lost: both bridge them at the reads'
  // period. The spline's knot after the gap needs the next read's first sample (its own read's
  // next is 1 µs later), so that read waits for it.
  for (const PoseInterpolation interpolation : {PoseInterpolation::Spline, PoseInterpolation::MatrixLerp}) {
    SCOPED_TRACE(interpolation == PoseInterpolation::Spline ? "spline" : "matrix-lerp");
    GapBridgeOptions o;
    o.interpolation = interpolation;
    GapBridge bridge(o);
    std::vector<Sample> out(bridge.max_outputs());
    std::vector<Sample> all;
    for (int i = 0; i < 400; ++i) {
      const int read = i / 4;
      if (read >= 50 && read < 53) continue;  // lost
      Sample s = sample_at(0.016 * read + 1e-6 * (i % 4), static_cast<std::uint64_t>(i));
      const std::size_t n = bridge.push(s, out);
      all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
    }
    const std::size_t n = bridge.flush(out);
    all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
    std::size_t bridged = 0;
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (k > 0) {
        EXPECT_GT(all[k].time, all[k - 1].time) << "in order";
      }
      if (!(all[k].flags & kBridged)) continue;
      ++bridged;
      EXPECT_LT(so3::rotation_angle(all[k].orientation, truth_q(all[k].time)), 0.01) << "t = " << all[k].time;
    }
    EXPECT_EQ(all.size(), 388u + bridged) << "every sample handed on once";
    EXPECT_EQ(bridged, 3u);
    EXPECT_EQ(bridge.counters().gaps, 1u);
    EXPECT_EQ(bridge.counters().clumped, 0u);
  }
}

TEST(GapBridge, AReadTooLongToWaitEndsItsGapUnbridged) {
  // After a gap, a read of more samples than may wait with the held one for the next read: the
  // gap goes through unbridged and counted, and nothing is lost or reordered.
  GapBridge bridge(GapBridgeOptions{});
  std::vector<Sample> out(bridge.max_outputs());
  std::vector<Sample> all;
  auto push = [&](const Sample& s) {
    const std::size_t n = bridge.push(s, out);
    all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  };
  std::uint64_t seq = 0;
  for (int i = 0; i < 20; ++i) push(sample_at(0.01 * i, seq++));
  const std::size_t read = GapBridge::kClumpHeld + 8;
  for (std::size_t k = 0; k < read; ++k) push(sample_at(0.25 + 1e-6 * static_cast<double>(k), seq++));
  for (int i = 1; i < 5; ++i) push(sample_at(0.25 + 0.01 * i, seq++));
  const std::size_t n = bridge.flush(out);
  all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  ASSERT_EQ(all.size(), seq);
  for (std::size_t k = 0; k < all.size(); ++k) EXPECT_EQ(all[k].sequence, k);
  EXPECT_EQ(bridge.counters().clumped, 1u);
  EXPECT_EQ(bridge.counters().gaps, 0u);
}

TEST(GapBridge, AGapLongerThanMaxGapPassesThrough) {
  GapBridgeOptions o;
  o.max_gap = 0.05;
  GapBridge bridge(o);
  std::vector<Sample> out(bridge.max_outputs());
  for (int i = 0; i <= 20; ++i) ASSERT_EQ(bridge.push(sample_at(0.01 * i, i), out), 1u);
  ASSERT_EQ(bridge.push(sample_at(0.30, 30), out), 1u);
  EXPECT_EQ(out[0].sequence, 30u);
  EXPECT_EQ(bridge.counters().too_long, 1u);
  EXPECT_EQ(bridge.counters().gaps, 0u);
  // After it, a short gap is bridged again (the spline restarted on the far side).
  for (int i = 31; i <= 40; ++i) ASSERT_EQ(bridge.push(sample_at(0.01 * i, i), out), 1u);
  EXPECT_EQ(bridge.push(sample_at(0.43, 43), out), 0u);
  EXPECT_EQ(bridge.push(sample_at(0.44, 44), out), 4u);
  EXPECT_EQ(out[0].flags & kBridged, kBridged);
}

TEST(GapBridge, ASampleOutOfOrderWhileHoldingReleasesTheHeldOneFirst) {
  GapBridge bridge(GapBridgeOptions{});
  std::vector<Sample> out(bridge.max_outputs());
  for (int i = 0; i <= 10; ++i) ASSERT_EQ(bridge.push(sample_at(0.01 * i, i), out), 1u);
  EXPECT_EQ(bridge.push(sample_at(0.15, 15), out), 0u);
  ASSERT_EQ(bridge.push(sample_at(0.12, 99), out), 2u);
  EXPECT_EQ(out[0].sequence, 15u);
  EXPECT_EQ(out[1].sequence, 99u);
  EXPECT_EQ(bridge.counters().gaps, 0u);
}

TEST(GapBridge, FlushHandsOnAHeldSampleAndNonFiniteSamplesPassThrough) {
  GapBridge bridge(GapBridgeOptions{});
  std::vector<Sample> out(bridge.max_outputs());
  for (int i = 0; i <= 10; ++i) ASSERT_EQ(bridge.push(sample_at(0.01 * i, i), out), 1u);
  Sample bad = sample_at(0.105, 77);
  bad.orientation = Quat(std::nan(""), 0, 0, 0);
  ASSERT_EQ(bridge.push(bad, out), 1u);  // for the window's gate to reject
  EXPECT_EQ(out[0].sequence, 77u);
  EXPECT_EQ(bridge.push(sample_at(0.15, 15), out), 0u);
  ASSERT_EQ(bridge.flush(out), 1u);
  EXPECT_EQ(out[0].sequence, 15u);
  EXPECT_EQ(bridge.flush(out), 0u);
}

TEST(GapBridge, RefusesBadOptions) {
  GapBridgeOptions o;
  o.max_gap = 0.0;
  EXPECT_THROW(GapBridge{o}, std::invalid_argument);
  o = GapBridgeOptions{};
  o.spline.velocity.estimator = geometric_splines::KnotVelocityEstimator::LocalQuadraticFit;
  EXPECT_THROW(GapBridge{o}, std::invalid_argument);
}

TEST(FixedRateResampler, A100HzStreamComesOutOnThe250HzGridCloseToTheTruth) {
  FixedRateResamplerOptions o;
  o.rate_hz = 250.0;
  FixedRateResampler r(o);
  std::vector<FairedPose> out(r.max_outputs());
  std::vector<FairedPose> all;
  double worst_delay = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double t = 0.003 + 0.01 * i;  // off the grid on purpose
    const std::size_t n = r.push(pose_at(t), out);
    for (std::size_t j = 0; j < n; ++j) {
      all.push_back(out[j]);
      worst_delay = std::max(worst_delay, t - out[j].time);
    }
  }
  ASSERT_GT(all.size(), 700u);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const FairedPose& g = all[i];
    EXPECT_NEAR(g.time * 250.0, std::round(g.time * 250.0), 1e-9) << "on the grid";
    if (i > 0) {
      EXPECT_NEAR(g.time - all[i - 1].time, 0.004, 1e-12) << "no grid time skipped or repeated";
    }
    EXPECT_LT(so3::rotation_angle(g.orientation, truth_q(g.time)), 1e-4) << "t = " << g.time;
    EXPECT_LT((g.position - truth_p(g.time)).norm(), 1e-4) << "t = " << g.time;
    EXPECT_EQ(g.flags, kHasPosition);
  }
  // The added delay: at most (lookahead + 1) input intervals.
  EXPECT_LE(worst_delay, static_cast<double>(r.delay_intervals()) * 0.01 + 1e-12);
  EXPECT_GT(worst_delay, 0.0);
}

TEST(FixedRateResampler, SamplesStampedInClumpsAreResampledAtTheTimesTheyWereTaken) {
  // 250 Hz read every 16 ms: four samples a read, stamped 1 µs apart, the newest at the time it
  // was taken. Their sampled steps (SampleGate) are the stamped ones until the rate is known
  // (after 1 s), then one interval. Through knots 1 µs apart the spline's grid poses were off
  // by up to 2 rad; placed at the times the samples were taken they are exact, and before the
  // rate is known the first sample of each read is the knot, late by up to a read.
  for (const PoseInterpolation interpolation : {PoseInterpolation::Spline, PoseInterpolation::MatrixLerp}) {
    SCOPED_TRACE(interpolation == PoseInterpolation::Spline ? "spline" : "matrix-lerp");
    FixedRateResamplerOptions o;
    o.rate_hz = 90.0;
    o.interpolation = interpolation;
    FixedRateResampler r(o);
    std::vector<FairedPose> out(r.max_outputs());
    double worst_late = 0.0, worst_early = 0.0;
    int late = 0, early = 0;
    double previous_stamp = 0.0;
    for (int i = 0; i < 1000; ++i) {
      const double taken = 0.004 * i;
      const double stamp = 0.016 * (i / 4) + 0.012 + 1e-6 * (i % 4 - 3);
      FairedPose p = pose_at(taken);
      p.time = stamp;
      p.step = i == 0 ? 0.0 : taken < 1.0 ? stamp - previous_stamp : 0.004;
      previous_stamp = stamp;
      const std::size_t n = r.push(p, out);
      for (std::size_t j = 0; j < n; ++j) {
        const FairedPose& g = out[j];
        const double e = so3::rotation_angle(g.orientation, truth_q(g.time));
        if (g.time > 1.1) {
          worst_late = std::max(worst_late, std::max(e, (g.position - truth_p(g.time)).norm()));
          ++late;
        } else {
          worst_early = std::max(worst_early, e);
          ++early;
        }
      }
    }
    EXPECT_GT(late, 230);
    EXPECT_GT(early, 80);
    EXPECT_LT(worst_late, interpolation == PoseInterpolation::Spline ? 1e-4 : 1e-3);
    EXPECT_LT(worst_early, 0.05);  // 12 ms late at about 1.5 rad/s at most
  }
}

TEST(FixedRateResampler, ALongStepRestartsWithoutGridPosesInTheGap) {
  FixedRateResamplerOptions o;
  o.rate_hz = 100.0;
  o.max_step = 0.1;
  FixedRateResampler r(o);
  std::vector<FairedPose> out(r.max_outputs());
  std::vector<FairedPose> all;
  auto feed = [&](double t) {
    const std::size_t n = r.push(pose_at(t), out);
    all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
  };
  for (int i = 0; i < 50; ++i) feed(0.01 * i + 0.001);
  for (int i = 0; i < 50; ++i) feed(1.0 + 0.01 * i + 0.001);
  EXPECT_EQ(r.restarts(), 1u);
  for (const FairedPose& g : all) EXPECT_FALSE(g.time > 0.5 && g.time < 1.0) << "a grid pose in the gap at " << g.time;
  EXPECT_TRUE(std::any_of(all.begin(), all.end(), [](const FairedPose& g) { return g.time > 1.0; }));
}

TEST(FixedRateResampler, GridPosesBetweenBridgedPosesAreBridgedAndPositionNeedsBoth) {
  // Bridged across a gap, or a held outlier's pose: either way not made from its own
  // measurement, and neither is a grid pose next to it.
  for (const std::uint32_t made : {std::uint32_t{kBridged}, std::uint32_t{kHeld}}) {
    SCOPED_TRACE(made);
    FixedRateResamplerOptions o;
    o.rate_hz = 1000.0;
    FixedRateResampler r(o);
    std::vector<FairedPose> out(r.max_outputs());
    std::vector<FairedPose> all;
    for (int i = 0; i < 40; ++i) {
      std::uint32_t flags = kHasPosition;
      if (i == 20) flags |= made;
      if (i >= 30) flags = 0;  // no position from here
      const std::size_t n = r.push(pose_at(0.01 * i + 0.0003, flags), out);  // knots off the grid
      all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
    }
    ASSERT_GT(all.size(), 300u);
    for (const FairedPose& g : all) {
      const bool near_made = g.time > 0.1903 && g.time < 0.2103;
      EXPECT_EQ(g.flags & kNotMeasured, near_made ? made : 0u) << "t = " << g.time;
      EXPECT_EQ((g.flags & kHasPosition) != 0, g.time < 0.2903) << "t = " << g.time;
    }
  }
}

TEST(FixedRateResampler, IgnoresPosesNotAfterThePreviousAndRefusesBadOptions) {
  FixedRateResampler r(FixedRateResamplerOptions{});
  std::vector<FairedPose> out(r.max_outputs());
  r.push(pose_at(0.1), out);
  EXPECT_EQ(r.push(pose_at(0.1), out), 0u);
  EXPECT_EQ(r.push(pose_at(0.05), out), 0u);
  FixedRateResamplerOptions o;
  o.rate_hz = 0.0;
  EXPECT_THROW(FixedRateResampler{o}, std::invalid_argument);
}

}  // namespace
}  // namespace posefair
