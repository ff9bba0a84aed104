// KNOWN BUGS in FairingWindow, reported and not fixed here. Each test states the promise it
// checks and fails on the current engine; they are DISABLED_ so the suite stays green until
// the engine is fixed (run them with --gtest_also_run_disabled_tests).
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
using testing::solver_name;

constexpr WindowSolver kSolvers[] = {WindowSolver::Linear, WindowSolver::GaussNewton, WindowSolver::DampedSweeps};

// sample.hpp: FairedPose::orientation is "hemisphere-continuous along the stream". A gap
// restart puts the first sample of the new window into w ≥ 0 (append(), n_ == 0) regardless of
// the sign the stream had, so a stream whose continuous quaternions have w < 0 flips sign at
// the restart: here outputs 99 (w = -0.398) and 100 (w = +0.416) are 0.02 apart as rotations
// but have a negative dot product.
TEST(FairingWindowKnownIssues, DISABLED_OutputStaysHemisphereContinuousAcrossAGapRestart) {
  // Constant rotation about x by 0.02 (half-angle) per sample: w = cos(0.02 i) < 0 from i = 79.
  const auto q = testing::sequence_with_linear_w1(200, Quat::Identity(), Vec3(0.02, 0.0, 0.0), Vec3::Zero());
  std::vector<Sample> in = samples_from(q);
  for (std::size_t i = 100; i < in.size(); ++i) in[i].time += 1.0;  // gap before sample 100
  for (WindowSolver solver : kSolvers) {
    SCOPED_TRACE(solver_name(solver));
    FairingWindow w(testing::smoothing_config(solver, 2, 0));
    const auto out = run(w, in);
    ASSERT_EQ(w.counters().restarts, 1u);
    for (std::size_t i = 1; i < out.size(); ++i) EXPECT_GE(out[i].orientation.dot(out[i - 1].orientation), 0.0) << i;
  }
}

// The ε promise is "hard" but the projection keeps only a relative 1e-9 margin
// (limit = ε·(1 − 1e-9)); rounding in z + d·(limit/r) is absolute, about ulp(|z|), so positions
// far from the origin end up past ε_t. Positions in metres offset by UTM-like coordinates
// (5e6 m) with ε_t = 5 mm: about 40 % of the 400 outputs exceed ε_t by up to 6e-10 m, for every
// solver (offset 1e5 m: about 25 outputs). The same happens for tiny ε_r (1e-8: ~130 of 400,
// by ~1e-16).
TEST(FairingWindowKnownIssues, DISABLED_TheBoundHoldsForPositionsFarFromTheOrigin) {
  auto motion = noisy_motion(1, true, 400, 0.05, 20.0);
  for (Vec3& p : motion.noisy.position) p = p / 1000.0 + Vec3(5e6, 5e6, 0.0);
  const auto in = samples_from(motion.noisy);
  for (WindowSolver solver : kSolvers) {
    SCOPED_TRACE(solver_name(solver));
    WindowConfig c = testing::smoothing_config(solver, 2, 0);
    c.epsilon_t = 0.005;
    FairingWindow w(c);
    const auto out = run(w, in);
    EXPECT_GT(w.counters().clamped, 0u);
    int violations = 0;
    for (const FairedPose& p : out) violations += (p.position - p.measured_position).norm() > c.epsilon_t ? 1 : 0;
    EXPECT_EQ(violations, 0);
  }
}

TEST(FairingWindowKnownIssues, DISABLED_TheBoundHoldsForATinyRotationEpsilon) {
  const auto motion = noisy_motion(1, false, 400, 0.05);
  const auto in = samples_from(motion.noisy);
  for (WindowSolver solver : kSolvers) {
    SCOPED_TRACE(solver_name(solver));
    WindowConfig c = testing::smoothing_config(solver, 2, 0);
    c.epsilon_r = 1e-8;
    const auto out = run(c, in);
    int violations = 0;
    for (const FairedPose& p : out) violations += so3::dist(p.orientation, p.measured) > c.epsilon_r ? 1 : 0;
    EXPECT_EQ(violations, 0);
  }
}

}  // namespace
}  // namespace posefair
