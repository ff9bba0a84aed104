// Gyro-aided fairing (core/gyro_aiding.hpp): with a gyroscope reading on every sample, the
// engine removes jitter without lag, estimates the gyro's bias and its time offset, bridges a
// reading or two that are missing, and leaves streams without a gyro exactly as they were.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "engine_test_support.hpp"
#include "../support/gyro_tracker_motion.hpp"
#include "posefair/core/fairing_window.hpp"

namespace posefair {
namespace {

constexpr double kDeg = M_PI / 180.0;

using posefair::testing::GyroTrackerSpec;
using GyroStream = posefair::testing::GyroTrackerStream;

GyroStream make_stream(double seconds, double jitter_deg, const Vec3& bias = Vec3::Zero(), double offset = 0.0,
                       const Quat& mounting = Quat::Identity()) {
  GyroTrackerSpec spec;
  spec.seconds = seconds;
  spec.jitter_deg = jitter_deg;
  spec.bias = bias;
  spec.offset = offset;
  spec.mounting = mounting;
  return posefair::testing::make_gyro_tracker_stream(spec);
}

std::vector<Sample> without_gyro(std::vector<Sample> s) {
  for (Sample& x : s) x.flags &= ~static_cast<std::uint32_t>(kHasGyro);
  return s;
}

// RMS angle (degrees) of the emitted poses to the truth, after the first second.
double rms_error_deg(const std::vector<FairedPose>& out, const std::vector<Quat>& truth) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const FairedPose& p : out) {
    if (p.time < 1.0) continue;
    const double a = so3::rotation_angle(p.orientation, truth[p.sequence]);
    sum += a * a;
    ++count;
  }
  return std::sqrt(sum / static_cast<double>(count)) / kDeg;
}

// Fairing alone at the best of a range of cutoffs.
double best_fairing_alone_deg(const GyroStream& g) {
  const std::vector<Sample> plain = without_gyro(g.samples);
  double best = 1e300;
  for (double fc : {1.0, 2.0, 4.0, 8.0, 16.0, 32.0}) {
    WindowConfig c;
    c.rate_hz = 200.0;
    c.cutoff_hz = fc;
    FairingWindow w(c);
    best = std::min(best, rms_error_deg(posefair::testing::run(w, plain), g.truth));
  }
  return best;
}

TEST(GyroAidedFairing, APerfectGyroRemovesJitterFarBelowFairingAlone) {
  const GyroStream g = make_stream(10.0, 1.0);
  FairingWindow w{WindowConfig{}};
  const double aided = rms_error_deg(posefair::testing::run(w, g.samples), g.truth);
  const double alone = best_fairing_alone_deg(g);
  EXPECT_TRUE(w.state().gyro.active);
  EXPECT_LT(aided, 0.35 * alone) << "aided " << aided << "°, fairing alone at its best cutoff " << alone << "°";
  EXPECT_LT(aided, 0.3);  // jitter 1°
}

TEST(GyroAidedFairing, SamplesStampedInClumpsAreIntegratedOverTheIntervalTheyWereTakenIn) {
  // Stamped when a read every 15 ms delivers them, three at a time 1 µs apart: integrated
  // between those stamps, the gyro turned nothing inside a clump and three intervals' worth
  // across the pause, and the aided output was worse than fairing alone (0.93° against 0.60°).
  // The window times its samples by the gate's sampled steps (one interval apart in a clump).
  const GyroStream g = make_stream(20.0, 1.0, Vec3(0.02, -0.03, 0.01));
  std::vector<Sample> clumped = g.samples;
  for (std::size_t i = 0; i < clumped.size(); ++i) {
    const double read = std::ceil(g.samples[i].time / 0.015 + 1e-9) * 0.015;
    clumped[i].time = i > 0 && read <= clumped[i - 1].time ? clumped[i - 1].time + 1e-6 : read;
  }
  auto error_from_4s = [&](const std::vector<FairedPose>& out) {
    double sum = 0.0;
    std::size_t count = 0;
    for (const FairedPose& p : out) {
      if (p.sequence < 800) continue;  // the rate of a clumped stream is known after 1 s; 4 s in
      sum += std::pow(so3::rotation_angle(p.orientation, g.truth[p.sequence]), 2);
      ++count;
    }
    return std::sqrt(sum / static_cast<double>(count)) / kDeg;
  };
  const double even = error_from_4s(posefair::testing::run(WindowConfig{}, g.samples));
  FairingWindow w{WindowConfig{}};
  const double aided = error_from_4s(posefair::testing::run(w, clumped));
  const double alone = error_from_4s(posefair::testing::run(WindowConfig{}, without_gyro(clumped)));
  EXPECT_TRUE(w.state().gyro.active);
  EXPECT_EQ(w.counters().restarts, 0u);
  EXPECT_LT(aided, 1.25 * even) << "clumped " << aided << "°, evenly stamped " << even << "°";
  EXPECT_LT(aided, 0.5 * alone) << "clumped " << aided << "°, fairing alone " << alone << "°";
}

TEST(GyroAidedFairing, EstimatesAConstantBiasAndIsNotHurtByIt) {
  const Vec3 bias(0.03, -0.02, 0.05);  // rad/s: 1.7, −1.1, 2.9 °/s
  const GyroStream g = make_stream(30.0, 1.0, bias);
  FairingWindow w{WindowConfig{}};
  const double aided = rms_error_deg(posefair::testing::run(w, g.samples, false), g.truth);
  const Vec3 estimated = w.state().gyro.bias;
  EXPECT_LT((estimated - bias).norm(), 0.005) << estimated.transpose();
  const GyroStream unbiased = make_stream(30.0, 1.0);
  FairingWindow u{WindowConfig{}};
  EXPECT_LT(aided, 1.2 * rms_error_deg(posefair::testing::run(u, unbiased.samples), unbiased.truth));
}

TEST(GyroAidedFairing, FindsTheTimeOffsetBetweenOrientationAndGyro) {
  const double offset = 0.004;
  const GyroStream g = make_stream(30.0, 1.0, Vec3::Zero(), offset);
  FairingWindow w{WindowConfig{}};
  const double aided = rms_error_deg(posefair::testing::run(w, g.samples, false), g.truth);
  const GyroAidingState s = w.state().gyro;
  EXPECT_TRUE(s.offset_estimated);
  EXPECT_NEAR(s.time_offset_s, offset, 0.0005);
  // Without the estimate the 4 ms offset costs accuracy on this fast motion.
  WindowConfig fixed;
  fixed.gyro.estimate_time_offset = false;
  FairingWindow f(fixed);
  const double unestimated = rms_error_deg(posefair::testing::run(f, g.samples, false), g.truth);
  EXPECT_LT(aided, 0.8 * unestimated) << "estimated " << aided << "°, not estimated " << unestimated << "°";
}

TEST(GyroAidedFairing, EstimatesBiasAndTimeOffsetTogether) {
  // Each alone would be found; together the offset's error follows the motion into the
  // bias's line unless the bias waits for the offset.
  const Vec3 bias(0.02, -0.03, 0.01);
  const GyroStream g = make_stream(20.0, 1.0, bias, 0.005);
  FairingWindow w{WindowConfig{}};
  posefair::testing::run(w, g.samples, false);
  const GyroAidingState s = w.state().gyro;
  EXPECT_NEAR(s.time_offset_s, 0.005, 0.0005);
  EXPECT_LT((s.bias - bias).norm(), 0.005) << s.bias.transpose();
}

TEST(GyroAidedFairing, AMountedGyroIsRotatedIntoTheBodyFrame) {
  const Quat mounting = so3::from_rotation_vector(Vec3(0.4, -1.1, 2.0));
  const GyroStream g = make_stream(10.0, 1.0, Vec3::Zero(), 0.0, mounting);
  WindowConfig c;
  c.gyro.mounting = mounting;
  FairingWindow w(c);
  const double aided = rms_error_deg(posefair::testing::run(w, g.samples), g.truth);
  EXPECT_LT(aided, 0.3);
  // Without the mounting the gyro disagrees with the motion and the result is far worse.
  FairingWindow wrong{WindowConfig{}};
  EXPECT_GT(rms_error_deg(posefair::testing::run(wrong, g.samples), g.truth), 2.0 * aided);
}

TEST(GyroAidedFairing, StreamsWithoutAGyroOrWithAidingOffAreUnchanged) {
  const GyroStream g = make_stream(3.0, 1.0);
  FairingWindow plain{WindowConfig{}};
  const std::vector<FairedPose> a = posefair::testing::run(plain, without_gyro(g.samples));
  WindowConfig off;
  off.gyro.enabled = false;
  FairingWindow disabled(off);
  const std::vector<FairedPose> b = posefair::testing::run(disabled, g.samples);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].orientation.coeffs(), b[i].orientation.coeffs()) << i;
  EXPECT_FALSE(disabled.state().gyro.active);
  EXPECT_EQ(disabled.state().gyro.intervals, 0u);
}

TEST(GyroAidedFairing, AGyroThatComesAndGoesRestartsTheWindow) {
  GyroStream g = make_stream(4.0, 1.0);
  for (std::size_t i = 300; i < 400; ++i) g.samples[i].flags &= ~static_cast<std::uint32_t>(kHasGyro);
  g.samples[400].gyro.x() = std::nan("");  // a non-finite reading counts as none (the window restarts at 401)
  FairingWindow w{WindowConfig{}};
  const std::vector<FairedPose> out = posefair::testing::run(w, g.samples);
  EXPECT_EQ(out.size(), g.samples.size());
  // 300 and 301 are bridged; the third missing reading in a row restarts the window (without
  // a gyro), and the gyro's return at 401 restarts it again.
  EXPECT_EQ(w.counters().gyro_bridged, static_cast<std::uint64_t>(kMaxBridgedGyroReadings));
  EXPECT_EQ(w.counters().restarts, 2u);
  EXPECT_TRUE(w.state().gyro.active);
  EXPECT_LT(rms_error_deg(out, g.truth), 1.0);
  for (const FairedPose& p : out) ASSERT_TRUE(p.orientation.coeffs().allFinite()) << p.sequence;
  EXPECT_TRUE(w.state().gyro.bias.allFinite());
}

// Readings dropped at `every` samples from the second second on, `run` in a row each time
// (gyro absent, or present but not finite); returns how many.
std::uint64_t drop_readings(std::vector<Sample>& samples, std::size_t every, std::size_t run) {
  std::uint64_t dropped = 0;
  for (std::size_t i = 200; i + run < samples.size(); i += every) {
    for (std::size_t k = i; k < i + run; ++k) {
      if (k % 2 == 0) {
        samples[k].flags &= ~static_cast<std::uint32_t>(kHasGyro);
      } else {
        samples[k].gyro.y() = std::nan("");
      }
      ++dropped;
    }
  }
  return dropped;
}

TEST(GyroAidedFairing, AFewDroppedReadingsAreBridgedWithoutARestartAndCostAlmostNothing) {
  const GyroStream g = make_stream(10.0, 1.0);
  FairingWindow full{WindowConfig{}};
  const std::vector<FairedPose> reference = posefair::testing::run(full, g.samples);
  for (std::size_t run = 1; run <= static_cast<std::size_t>(kMaxBridgedGyroReadings); ++run) {
    std::vector<Sample> samples = g.samples;
    const std::uint64_t dropped = drop_readings(samples, 37, run);
    FairingWindow w{WindowConfig{}};
    const std::vector<FairedPose> out = posefair::testing::run(w, samples);
    ASSERT_EQ(out.size(), reference.size());
    EXPECT_EQ(w.counters().restarts, 0u) << run << " in a row";
    EXPECT_EQ(w.counters().gyro_bridged, dropped);
    EXPECT_TRUE(w.state().gyro.active);
    // Each bridged reading is the line between its neighbours' (the motion's rate changes by
    // up to ~25 rad/s² here): the output stays within a small fraction of the jitter of what
    // the full gyro gives, at every sample, and the overall error barely moves.
    double worst = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i)
      worst = std::max(worst, so3::rotation_angle(out[i].orientation, reference[i].orientation));
    EXPECT_LT(worst / kDeg, 0.1) << run << " in a row";
    EXPECT_LT(rms_error_deg(out, g.truth), 1.05 * rms_error_deg(reference, g.truth)) << run << " in a row";
  }
}

TEST(GyroAidedFairing, BridgedReadingsDoNotSpoilTheBiasOrTheOffset) {
  const Vec3 bias(0.02, -0.03, 0.01);
  GyroStream g = make_stream(20.0, 1.0, bias, 0.005);
  drop_readings(g.samples, 23, 2);
  FairingWindow w{WindowConfig{}};
  posefair::testing::run(w, g.samples, false);
  EXPECT_EQ(w.counters().restarts, 0u);
  const GyroAidingState s = w.state().gyro;
  EXPECT_NEAR(s.time_offset_s, 0.005, 0.0005);
  EXPECT_LT((s.bias - bias).norm(), 0.005) << s.bias.transpose();
  // Each interval fed once, bridged ones too: as many as with every reading there.
  FairingWindow full{WindowConfig{}};
  posefair::testing::run(full, make_stream(20.0, 1.0, bias, 0.005).samples, false);
  EXPECT_EQ(s.intervals, full.state().gyro.intervals);
}

}  // namespace
}  // namespace posefair
