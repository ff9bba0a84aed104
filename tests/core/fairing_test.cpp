#include "posefair/core/fairing.hpp"

#include <random>
#include <stdexcept>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace posefair
