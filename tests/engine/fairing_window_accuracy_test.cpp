// What the FairingWindow solvers compute: they smooth noisy data toward the truth, Linear and
// Gauss–Newton agree, motions the order-m energy does not penalise pass through unchanged,
// and quaternion signs in the input do not matter.
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../core/test_sequences.hpp"
#include "engine_test_support.hpp"
#include "posefair/core/fairing_window.hpp"

namespace posefair {
namespace {

using testing::noisy_motion;
using testing::run;
using testing::samples_from;
using testing::smoothing_config;
using testing::solver_name;

double rms_rotation_error(const std::vector<FairedPose>& out, const PoseSequence& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double d = so3::dist(out[i].orientation, truth.orientation[i]);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(out.size()));
}

double rms_rotation_error(const PoseSequence& noisy, const PoseSequence& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    const double d = so3::dist(noisy.orientation[i], truth.orientation[i]);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(noisy.size()));
}

double rms_position_error(const std::vector<FairedPose>& out, const PoseSequence& truth, bool raw) {
  double sum = 0.0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Vec3 p = raw ? out[i].measured_position : out[i].position;
    sum += (p - truth.position[i]).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(out.size()));
}

TEST(FairingWindowAccuracy, SmoothingBringsTheStreamCloserToTheTruth) {
  // 10 s at 100 Hz, rotation noise up to 0.02 (dist), 10 mm position noise, a 4 Hz cutoff.
  // Measured ratios (3 seeds, worst): lag 3 ≈ 0.36 (both orders); lag 0 on the slower
  // motion ≈ 0.52 (order 2) and 0.60 (order 3).
  struct Case {
    int lag;
    double cycles;
    double max_ratio;
  };
  const Case cases[] = {{3, 4.0, 0.5}, {0, 2.0, 0.7}};
  for (WindowSolver solver : {WindowSolver::Linear, WindowSolver::GaussNewton}) {
    for (int order : {2, 3}) {
      for (const Case& cs : cases) {
        for (std::uint64_t seed : {1u, 2u, 3u}) {
          SCOPED_TRACE(std::string(solver_name(solver)) + " order=" + std::to_string(order) + " lag=" +
                       std::to_string(cs.lag) + " seed=" + std::to_string(seed));
          const auto motion = noisy_motion(seed, true, 1000, 0.02, 10.0, cs.cycles);
          const auto out = run(smoothing_config(solver, order, cs.lag), samples_from(motion.noisy));
          ASSERT_EQ(out.size(), motion.truth.size());
          const double raw = rms_rotation_error(motion.noisy, motion.truth);
          const double faired = rms_rotation_error(out, motion.truth);
          EXPECT_LT(faired, cs.max_ratio * raw) << "raw " << raw << " faired " << faired;
          const double raw_t = rms_position_error(out, motion.truth, true);
          const double faired_t = rms_position_error(out, motion.truth, false);
          EXPECT_LT(faired_t, cs.max_ratio * raw_t) << "raw " << raw_t << " faired " << faired_t;
        }
      }
    }
  }
}

TEST(FairingWindowAccuracy, LinearAndGaussNewtonAgree) {
  // Linear neglects terms of order (motion per sample) × (correction); three Gauss–Newton
  // iterations converge on the exact minimiser. On this data the largest difference measured
  // was about 4.9e-4 (dist on S³); the tolerance leaves a factor of two.
  double worst = 0.0;
  for (int order : {2, 3}) {
    for (int lag : {0, 3}) {
      for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
        SCOPED_TRACE("order=" + std::to_string(order) + " lag=" + std::to_string(lag) + " seed=" + std::to_string(seed));
        const auto motion = noisy_motion(seed, false, 1000, 0.02, 0.0, 2.0);
        const auto in = samples_from(motion.noisy);
        const auto linear = run(smoothing_config(WindowSolver::Linear, order, lag), in);
        const auto gn = run(smoothing_config(WindowSolver::GaussNewton, order, lag, 3), in);
        ASSERT_EQ(linear.size(), gn.size());
        double d = 0.0;
        for (std::size_t i = 0; i < linear.size(); ++i) d = std::max(d, so3::dist(linear[i].orientation, gn[i].orientation));
        EXPECT_LT(d, 1e-3);
        worst = std::max(worst, d);
      }
    }
  }
  std::printf("[          ] largest Linear vs GaussNewton difference: %.3g (dist on S^3)\n", worst);
}

TEST(FairingWindowAccuracy, GaussNewtonHasConvergedAfterThreeIterations) {
  const auto motion = noisy_motion(6, false, 500, 0.02, 0.0, 2.0);
  const auto in = samples_from(motion.noisy);
  const auto three = run(smoothing_config(WindowSolver::GaussNewton, 3, 3, 3), in);
  const auto many = run(smoothing_config(WindowSolver::GaussNewton, 3, 3, 20), in);
  ASSERT_EQ(three.size(), many.size());
  for (std::size_t i = 0; i < three.size(); ++i) EXPECT_LT(so3::dist(three[i].orientation, many[i].orientation), 1e-6) << i;
}

TEST(FairingWindowAccuracy, PositionsAreSolvedIdenticallyByLinearAndGaussNewton) {
  // Positions are linear: both solvers solve the same banded system exactly (the linear
  // solver as z_k + Σ h_j Δz_j, so they agree to rounding: ~1e-11 of positions of ~400).
  const auto motion = noisy_motion(7, true, 300, 0.02, 10.0);
  const auto in = samples_from(motion.noisy);
  const auto linear = run(smoothing_config(WindowSolver::Linear, 3, 2), in);
  const auto gn = run(smoothing_config(WindowSolver::GaussNewton, 3, 2), in);
  ASSERT_EQ(linear.size(), gn.size());
  for (std::size_t i = 0; i < linear.size(); ++i) EXPECT_LT((linear[i].position - gn[i].position).norm(), 1e-8) << i;
}

// Noiseless input the order-m energy does not penalise: W^m = 0 (and D^m p = 0).
struct ExactMotion {
  std::vector<Sample> samples;
};

ExactMotion exact_motion(int order, std::uint64_t seed, std::size_t n = 150) {
  std::mt19937_64 rng(seed);
  const Quat start = testing::random_unit_quaternion(rng);
  const Vec3 a = 0.03 * testing::random_direction(rng);
  const Vec3 b = order == 3 ? Vec3(4e-4 * testing::random_direction(rng)) : Vec3::Zero();
  const auto q = testing::sequence_with_linear_w1(n, start, a, b);
  ExactMotion m{samples_from(q)};
  const Vec3 p0(0.3, -0.2, 0.1), v(0.002, 0.001, -0.003), acc(1e-5, -2e-5, 1e-5);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i);
    m.samples[i].position = p0 + v * t + (order == 3 ? Vec3(acc * t * t) : Vec3::Zero());
    m.samples[i].flags |= kHasPosition;
  }
  return m;
}

TEST(FairingWindowAccuracy, MotionWithoutOrderMEnergyPassesThroughUnchanged) {
  // Order 2: constant angular velocity (and constant linear velocity); order 3: constant
  // angular acceleration (W¹ linear in i) and constant linear acceleration.
  // Gauss–Newton gets 10 iterations: its newest sample starts from a constant-velocity
  // prediction, which is off by the acceleration under order 3, and its update (identity
  // Jacobians for log) converges only linearly from there, by about 0.15 per iteration on this
  // data (3 iterations: up to 6e-8; see GaussNewtonSettlesOnConstantAcceleration).
  for (WindowSolver solver : {WindowSolver::Linear, WindowSolver::GaussNewton}) {
    for (int order : {2, 3}) {
      for (int lag : {0, 3}) {
        for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
          SCOPED_TRACE(std::string(solver_name(solver)) + " order=" + std::to_string(order) + " lag=" +
                       std::to_string(lag) + " seed=" + std::to_string(seed));
          const auto m = exact_motion(order, seed);
          const auto out = run(smoothing_config(solver, order, lag, /*iterations=*/10), m.samples);
          ASSERT_EQ(out.size(), m.samples.size());
          for (std::size_t i = 0; i < out.size(); ++i) {
            ASSERT_LT(so3::dist(out[i].orientation, m.samples[i].orientation), 1e-9) << i;
            ASSERT_LT((out[i].position - m.samples[i].position).norm(), 1e-9) << i;
          }
        }
      }
    }
  }
}

TEST(FairingWindowAccuracy, ConstantVelocityIsAFixedPointOfGaussNewtonFromTheFirstIteration) {
  // The warm start predicts constant velocity exactly, so no iteration count is needed.
  for (int lag : {0, 3}) {
    for (int iterations : {1, 3}) {
      SCOPED_TRACE("lag=" + std::to_string(lag) + " iterations=" + std::to_string(iterations));
      const auto m = exact_motion(2, 5);
      const auto out = run(smoothing_config(WindowSolver::GaussNewton, 2, lag, iterations), m.samples);
      for (std::size_t i = 0; i < out.size(); ++i) ASSERT_LT(so3::dist(out[i].orientation, m.samples[i].orientation), 1e-12) << i;
    }
  }
}

TEST(FairingWindowAccuracy, GaussNewtonSettlesOnConstantAcceleration) {
  // With the default-ish 3 iterations the order-3 fixed point is held to about 6e-8 (measured
  // over these seeds); a regression in the update or the warm start shows up as far more.
  double worst = 0.0;
  for (int lag : {0, 3}) {
    for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
      const auto m = exact_motion(3, seed);
      const auto out = run(smoothing_config(WindowSolver::GaussNewton, 3, lag, 3), m.samples);
      for (std::size_t i = 0; i < out.size(); ++i) worst = std::max(worst, so3::dist(out[i].orientation, m.samples[i].orientation));
    }
  }
  EXPECT_LT(worst, 5e-7);
}

TEST(FairingWindowAccuracy, ConstantAccelerationIsSmoothedByOrderTwo) {
  // The control for the test above: order 2 does penalise angular acceleration, so the same
  // check fails there (it is not passing because nothing moves).
  for (WindowSolver solver : {WindowSolver::Linear, WindowSolver::GaussNewton}) {
    SCOPED_TRACE(solver_name(solver));
    const auto m = exact_motion(3, 1);
    const auto out = run(smoothing_config(solver, 2, 3), m.samples);
    double worst = 0.0, worst_t = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      worst = std::max(worst, so3::dist(out[i].orientation, m.samples[i].orientation));
      worst_t = std::max(worst_t, (out[i].position - m.samples[i].position).norm());
    }
    EXPECT_GT(worst, 1e-5);
    EXPECT_GT(worst_t, 1e-5);
  }
}

TEST(FairingWindowAccuracy, HemisphereFlipsInTheInputDoNotChangeTheOutputRotation) {
  const auto motion = noisy_motion(21, true, 300, 0.03, 5.0);
  const auto in = samples_from(motion.noisy);
  std::vector<Sample> flipped = in;
  std::mt19937_64 rng(3);
  for (Sample& s : flipped)
    if (rng() % 2) s.orientation.coeffs() = -s.orientation.coeffs();
  flipped[0].orientation.coeffs() = -in[0].orientation.coeffs();  // the first one for sure
  struct Case {
    WindowSolver solver;
    BoundPolicy bound;
  };
  for (const Case& cs : {Case{WindowSolver::Linear, BoundPolicy::Sample}, Case{WindowSolver::GaussNewton, BoundPolicy::Sample},
                         Case{WindowSolver::GaussNewton, BoundPolicy::Window}, Case{WindowSolver::DampedSweeps, BoundPolicy::Sample},
                         Case{WindowSolver::DampedSweeps, BoundPolicy::Window}}) {
    for (int order : {2, 3}) {
      SCOPED_TRACE(std::string(solver_name(cs.solver)) + " bound=" + testing::bound_name(cs.bound) + " order=" + std::to_string(order));
      WindowConfig c = smoothing_config(cs.solver, order, 3);
      c.bound = cs.bound;
      c.continuity = 0.5;
      c.epsilon_r = 0.02;
      c.epsilon_t = 4.0;
      const auto a = run(c, in);
      const auto b = run(c, flipped);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_LT(so3::dist(a[i].orientation, b[i].orientation), 1e-12) << i;
        ASSERT_EQ(a[i].position, b[i].position) << i;
        // measured is the input with its own sign.
        ASSERT_GE(b[i].measured.dot(flipped[i].orientation), 0.0) << i;
        // The output is hemisphere-continuous along the stream.
        if (i > 0) {
          ASSERT_GE(b[i].orientation.dot(b[i - 1].orientation), 0.0) << i;
        }
      }
    }
  }
}

}  // namespace
}  // namespace posefair
