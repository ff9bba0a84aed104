#include "posefair/core/fairing.hpp"

#include <limits>
#include <random>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "posefair/core/difference_operators.hpp"
#include "posefair/core/fairing_sweep.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair {
namespace {

SyntheticMotion motion(std::uint64_t seed, bool with_position = true, std::size_t n = 100) {
  SyntheticMotionSpec spec;
  spec.seed = seed;
  spec.with_position = with_position;
  spec.samples = n;
  return make_synthetic_motion(spec);
}

TEST(Fairing, EveryOutputStaysWithinTheBoundOfItsInput) {
  for (int m : {2, 3}) {
    for (OperatorVariant v : {OperatorVariant::Corrected, OperatorVariant::Printed}) {
      for (double eps_r : {0.005, 0.02, 0.05}) {
        for (double eps_t : {2.0, 8.0}) {
          const auto in = motion(static_cast<std::uint64_t>(m * 100 + eps_r * 1000));
          FairingParams p;
          p.order = m;
          p.variant = v;
          p.epsilon_r = eps_r;
          p.epsilon_t = eps_t;
          p.lambda_t = 0.1;
          p.max_iterations = 500;
          const auto r = fair(in.noisy, p);
          EXPECT_EQ(r.stop, StopReason::Bound);
          // Tight bounds may stop before the first sweep; the loosest must allow one.
          if (eps_r >= 0.05 && eps_t >= 8.0) {
            EXPECT_GT(r.iterations, 0);
          }
          for (std::size_t i = 0; i < in.noisy.size(); ++i) {
            ASSERT_LT(so3::dist(r.poses.orientation[i], in.noisy.orientation[i]), eps_r);
            ASSERT_LT((r.poses.position[i] - in.noisy.position[i]).norm(), eps_t);
          }
          EXPECT_LT(r.max_dist_r, eps_r);
          EXPECT_LT(r.max_deviation_t, eps_t);
          if (r.iterations > 0) {
            EXPECT_LT(r.rotational_energy_after, r.rotational_energy_before);
            EXPECT_LT(r.translational_energy_after, r.translational_energy_before);
          }
        }
      }
    }
  }
}

TEST(Fairing, KeepsTheLastIterateThatSatisfiesTheBound) {
  // ERRATA item 5: one more sweep than reported would break the bound.
  const auto in = motion(9);
  FairingParams p;
  p.epsilon_r = 0.03;
  p.max_iterations = 1000;
  const auto r = fair(in.noisy, p);
  ASSERT_EQ(r.stop, StopReason::Bound);
  FairingParams one_more = p;
  one_more.epsilon_r = 10.0;
  one_more.epsilon_t = 1e9;
  one_more.max_iterations = r.iterations + 1;
  const auto r2 = fair(in.noisy, one_more);
  double worst = 0.0;
  for (std::size_t i = 0; i < in.noisy.size(); ++i) worst = std::max(worst, so3::dist(r2.poses.orientation[i], in.noisy.orientation[i]));
  EXPECT_GE(worst, p.epsilon_r);
}

TEST(Fairing, OrientationOnlyStreamsAreTheCommonCase) {
  const auto in = motion(4, /*with_position=*/false);
  FairingParams p;
  p.max_iterations = 20;
  const auto r = fair(in.noisy, p);
  EXPECT_FALSE(r.poses.has_position());
  EXPECT_EQ(r.iterations, 20);
  EXPECT_EQ(r.stop, StopReason::IterationCap);
  EXPECT_EQ(r.poses.time, in.noisy.time);
  EXPECT_LT(r.rotational_energy_after, 0.5 * r.rotational_energy_before);
}

TEST(Fairing, ZeroIterationsReturnsTheInput) {
  const auto in = motion(5);
  FairingParams p;
  p.max_iterations = 0;
  const auto r = fair(in.noisy, p);
  EXPECT_EQ(r.iterations, 0);
  for (std::size_t i = 0; i < in.noisy.size(); ++i) {
    EXPECT_LT(so3::dist(r.poses.orientation[i], in.noisy.orientation[i]), 1e-15);
    EXPECT_GE(r.poses.orientation[i].dot(in.noisy.orientation[i]), 0.0);
  }
}

TEST(Fairing, HemisphereFlipsInTheInputDoNotChangeTheResult) {
  const auto in = motion(6);
  PoseSequence flipped = in.noisy;
  std::mt19937_64 rng(1);
  for (Quat& q : flipped.orientation)
    if (rng() % 2) q.coeffs() = -q.coeffs();
  FairingParams p;
  p.epsilon_r = 0.04;
  const auto a = fair(in.noisy, p);
  const auto b = fair(flipped, p);
  EXPECT_EQ(a.iterations, b.iterations);
  for (std::size_t i = 0; i < in.noisy.size(); ++i) {
    // Each output carries its own input's sign; as rotations they are identical.
    EXPECT_EQ(so3::aligned_to(b.poses.orientation[i], a.poses.orientation[i]).coeffs(), a.poses.orientation[i].coeffs()) << i;
    EXPECT_GE(b.poses.orientation[i].dot(flipped.orientation[i]), 0.0) << i;
  }
}

TEST(Fairing, ConvergenceStopWhenNothingMoves) {
  // Ten samples under m = 2 settle on a geodesic quickly.
  const auto in = motion(7, false, 10);
  FairingParams p;
  p.order = 2;
  p.max_iterations = 100000;
  p.lambda_r = 0.5;
  p.step_tolerance = 1e-9;
  const auto r = fair(in.noisy, p);
  EXPECT_EQ(r.stop, StopReason::Converged);
  EXPECT_LT(r.iterations, 100000);
}

TEST(Fairing, TheVariantsAreSelectableAndDiffer) {
  const auto in = motion(8, false);
  FairingParams p;
  p.max_iterations = 10;
  const auto corrected = fair(in.noisy, p);
  p.variant = OperatorVariant::Printed;
  const auto printed = fair(in.noisy, p);
  EXPECT_GT(so3::dist(corrected.poses.orientation[50], printed.poses.orientation[50]), 1e-6);
}

TEST(Fairing, ASequenceTooShortForTheOrderIsAClearError) {
  const auto in = motion(1, true, 3);
  FairingParams p;
  p.order = 3;
  try {
    fair(in.noisy, p);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("at least 4 samples, got 3"));
  }
  p.order = 2;
  EXPECT_NO_THROW(fair(in.noisy, p));
  EXPECT_THROW(fair(PoseSequence{}, p), std::invalid_argument);
}

TEST(Fairing, BadParametersAndMismatchedPositionsAreErrors) {
  const auto in = motion(2);
  FairingParams p;
  p.order = 4;
  EXPECT_THROW(fair(in.noisy, p), std::invalid_argument);
  p = {};
  p.lambda_r = 0.0;
  EXPECT_THROW(fair(in.noisy, p), std::invalid_argument);
  p = {};
  p.epsilon_r = -1;
  EXPECT_THROW(fair(in.noisy, p), std::invalid_argument);
  p = {};
  PoseSequence broken = in.noisy;
  broken.position.pop_back();
  EXPECT_THROW(fair(broken, p), std::invalid_argument);
}

// fair() before its sweep was fused (fairing_sweep.hpp): the operators on quaternions, one
// after the other, as the real-time engine still calls them. The reference for the tests below.
FairingResult operator_loop(const PoseSequence& input, const FairingParams& params) {
  const std::size_t n = input.size();
  const bool with_p = input.has_position();
  std::vector<Quat> q0(input.orientation.begin(), input.orientation.end());
  for (Quat& q : q0) q.normalize();
  so3::make_continuous(q0);
  const std::vector<Vec3>& p0 = input.position;
  std::vector<Quat> q = q0, q_next(n), target(n);
  std::vector<Vec3> u(n - 1), p = p0, p_next, p_target(with_p ? n : 0);
  FairingResult r;
  for (int k = 0; k < params.max_iterations; ++k) {
    q_next = q;
    damped_rotation_sweep(params.order, params.variant, params.lambda_r, q_next, u, target);
    if (with_p) {
      p_next = p;
      damped_position_sweep(params.order, params.lambda_t, p_next, p_target);
    }
    bool within = true;
    double step = 0.0;
    for (std::size_t i = 0; i < n && within; ++i)
      within = so3::dist(q0[i], q_next[i]) < params.epsilon_r && (!with_p || (p_next[i] - p0[i]).norm() < params.epsilon_t);
    if (!within) {
      r.stop = StopReason::Bound;
      break;
    }
    for (std::size_t i = 0; i < n; ++i) {
      step = std::max(step, so3::dist(q[i], q_next[i]));
      if (with_p) step = std::max(step, (p_next[i] - p[i]).norm());
    }
    q.swap(q_next);
    if (with_p) p.swap(p_next);
    r.iterations = k + 1;
    if (step <= params.step_tolerance) {
      r.stop = StopReason::Converged;
      break;
    }
  }
  r.poses.orientation.resize(n);
  for (std::size_t i = 0; i < n; ++i) r.poses.orientation[i] = so3::aligned_to(q[i], input.orientation[i]);
  r.poses.position = p;
  return r;
}

double largest_difference(const std::vector<Quat>& a, const std::vector<Quat>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i].coeffs() - b[i].coeffs()).cwiseAbs().maxCoeff());
  return d;
}

// One sweep, every order, variant and length (lengths below and above the lane width reach
// the one-at-a-time remainder and the ends): the fused sweep against the operators.
TEST(FairingSweep, OneSweepAgreesWithTheOperatorsToRoundingAndPositionsBitForBit) {
  for (int m : {2, 3}) {
    for (OperatorVariant v : {OperatorVariant::Corrected, OperatorVariant::Printed}) {
      for (std::size_t n : {3u, 4u, 5u, 6u, 7u, 8u, 9u, 12u, 13u, 61u}) {
        if (n < static_cast<std::size_t>(min_samples_for_order(m))) continue;
        const auto in = motion(n + 10u * static_cast<std::size_t>(m), true, n);
        FairingParams p;
        p.order = m;
        p.variant = v;
        p.lambda_r = 0.3;
        std::vector<Quat> q0 = in.noisy.orientation;
        so3::make_continuous(q0);
        FairingSweep sweep(p, q0, in.noisy.position);
        EXPECT_TRUE(sweep.sweep().moved);
        sweep.accept();
        std::vector<Quat> q;
        std::vector<Vec3> pos;
        sweep.current(q, pos);

        std::vector<Quat> q_ref = q0, target(n);
        std::vector<Vec3> u(n - 1), p_ref = in.noisy.position, p_target(n);
        damped_rotation_sweep(m, v, p.lambda_r, q_ref, u, target);
        damped_position_sweep(m, p.lambda_t, p_ref, p_target);
        EXPECT_LT(largest_difference(q, q_ref), 1e-15) << "m " << m << " n " << n;
        for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(pos[i], p_ref[i]) << "m " << m << " n " << n << " i " << i;
      }
    }
  }
}

// The whole loop: 100 sweeps, or until the bound or the tolerance stops it, on several inputs.
TEST(FairingSweep, FairAgreesWithTheOperatorLoopTo1e12) {
  struct Case {
    int order;
    OperatorVariant variant;
    bool with_position;
    std::size_t n;
    double eps_r, eps_t, tolerance;
    int iterations;
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Case cases[] = {
      {3, OperatorVariant::Corrected, true, 300, kInf, kInf, 0.0, 100},   // the paper's timing case
      {3, OperatorVariant::Printed, false, 57, kInf, kInf, 0.0, 100},
      {2, OperatorVariant::Corrected, true, 100, 0.03, 5.0, 0.0, 1000},   // stops at the bound
      {2, OperatorVariant::Printed, false, 33, kInf, kInf, 0.0, 100},
      {3, OperatorVariant::Corrected, false, 100, 0.05, kInf, 0.0, 1000},  // stops at the bound
      {2, OperatorVariant::Corrected, false, 10, kInf, kInf, 1e-9, 100000},  // converges
  };
  for (const Case& c : cases) {
    const auto in = motion(c.n, c.with_position, c.n);
    FairingParams p;
    p.order = c.order;
    p.variant = c.variant;
    p.epsilon_r = c.eps_r;
    p.epsilon_t = c.eps_t;
    p.step_tolerance = c.tolerance;
    p.max_iterations = c.iterations;
    if (c.tolerance > 0.0) p.lambda_r = 0.5;
    const auto fused = fair(in.noisy, p);
    const auto ref = operator_loop(in.noisy, p);
    EXPECT_EQ(fused.stop, ref.stop) << c.n;
    EXPECT_EQ(fused.iterations, ref.iterations) << c.n;
    EXPECT_LT(largest_difference(fused.poses.orientation, ref.poses.orientation), 1e-12) << c.n;
    EXPECT_EQ(fused.poses.position, ref.poses.position) << c.n;
  }
  // Nothing moves at all: with no tolerance, the loop stops as soon as a sweep changes nothing.
  PoseSequence still;
  for (int i = 0; i < 20; ++i) {
    still.time.push_back(0.01 * i);
    still.orientation.push_back(Quat(0.5, 0.5, 0.5, 0.5));
  }
  FairingParams p;
  const auto fused = fair(still, p), ref = operator_loop(still, p);
  EXPECT_EQ(fused.stop, StopReason::Converged);
  EXPECT_EQ(ref.stop, StopReason::Converged);
  EXPECT_LT(largest_difference(fused.poses.orientation, ref.poses.orientation), 1e-15);
}

}  // namespace
}  // namespace posefair
