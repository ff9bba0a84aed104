// Gyro-aided fairing (core/gyro_aiding.hpp): with a gyroscope reading on every sample, the
// engine removes jitter without lag, estimates the gyro's bias and its time offset, and leaves
// streams without a gyro exactly as they were.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "engine_test_support.hpp"
#include "posefair/core/fairing_window.hpp"

namespace posefair {
namespace {

constexpr double kRate = 200.0;
constexpr double kDeg = M_PI / 180.0;

// Body angular velocity of a lively motion (rad/s): several hundred °/s at times.
Vec3 body_rate(double t) {
  return {4.0 * std::sin(2.0 * M_PI * 0.7 * t), 3.0 * std::cos(2.0 * M_PI * 0.45 * t + 0.3), 2.5 * std::sin(2.0 * M_PI * 1.3 * t + 1.0)};
}

struct GyroStream {
  std::vector<Quat> truth;
  std::vector<Sample> samples;
};

// seconds of motion at kRate: the orientation integrated finely from body_rate, measured with
// white jitter of jitter_deg RMS angle; each sample's gyro reads the rate at t − offset (the
// reading stamped t + offset measured the motion at t), plus bias, in a frame rotated by
// mounting⁻¹ from the body.
GyroStream make_stream(double seconds, double jitter_deg, const Vec3& bias = Vec3::Zero(), double offset = 0.0,
                       const Quat& mounting = Quat::Identity(), std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, jitter_deg * kDeg / std::sqrt(3.0));
  GyroStream g;
  Quat q = Quat::Identity();
  const int substeps = 20;
  const auto count = static_cast<std::size_t>(seconds * kRate);
  for (std::size_t i = 0; i < count; ++i) {
    const double t = static_cast<double>(i) / kRate;
    g.truth.push_back(q);
    Sample s;
    s.sequence = i;
    s.time = t;
    s.orientation = (q * so3::from_rotation_vector(Vec3(n(rng), n(rng), n(rng)))).normalized();
    s.gyro = mounting.conjugate() * body_rate(t - offset) + bias;
    s.flags = kHasGyro;
    g.samples.push_back(s);
    for (int k = 0; k < substeps; ++k) {
      const double h = 1.0 / (kRate * substeps);
      q = (q * so3::from_rotation_vector(body_rate(t + (k + 0.5) * h) * h)).normalized();
    }
  }
  return g;
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
    c.rate_hz = kRate;
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
  FairingWindow w{WindowConfig{}};
  const std::vector<FairedPose> out = posefair::testing::run(w, g.samples);
  EXPECT_EQ(out.size(), g.samples.size());
  EXPECT_EQ(w.counters().restarts, 2u);
  EXPECT_TRUE(w.state().gyro.active);
  EXPECT_LT(rms_error_deg(out, g.truth), 1.0);
}

}  // namespace
}  // namespace posefair
