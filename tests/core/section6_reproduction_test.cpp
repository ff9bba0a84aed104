// Lee & Shin, Section 6, reproduced: 100 samples of a smooth orientation curve perturbed by
// random rotations with ‖δ‖ < 0.1 (positions in a 400 mm cube, ‖δ‖ < 10 mm), averaged over
// several seeds. docs/fairing.md shows the same traces as plots and says which claims hold.
#include <limits>

#include <gtest/gtest.h>

#include "posefair/core/difference_operators.hpp"
#include "posefair/core/fairing_study.hpp"

namespace posefair {
namespace {

// Mean over seeds 1..5 at each iteration (unbounded: ε = ∞), as docs/fairing.md plots it.
std::vector<FairingTracePoint> mean_trace(int order, double lambda_r, int iterations) {
  FairingParams p;
  p.order = order;
  p.lambda_r = lambda_r;
  p.max_iterations = iterations;
  return posefair::mean_trace(SyntheticMotionSpec{}, 5, p);
}

// Claim 1: "The average error of the third order algorithm converges within the range of
// perturbation. However, the second order algorithm deforms the data too much."
// Holds, given enough iterations: at 1000 sweeps m = 3 stays inside the perturbation bound
// (0.1) while m = 2 has left it. At 100 sweeps the two are still alike.
TEST(Section6, ThirdOrderStaysWithinThePerturbationWhileSecondOrderDeforms) {
  const auto m2 = mean_trace(2, 0.1, 1000);
  const auto m3 = mean_trace(3, 0.1, 1000);
  EXPECT_LT(m3[1000].mean_error_to_input, 0.1);
  EXPECT_GT(m2[1000].mean_error_to_input, 0.1);
  EXPECT_LT(m3[1000].mean_error_to_truth, 0.5 * m2[1000].mean_error_to_truth);
  // The m = 3 error has levelled off: the last 700 sweeps add less than 15%.
  EXPECT_LT(m3[1000].mean_error_to_input, 1.15 * m3[300].mean_error_to_input);
  // Both first remove noise: error to the clean truth falls well below the input's.
  EXPECT_LT(m3[100].mean_error_to_truth, 0.6 * m3[0].mean_error_to_truth);
  EXPECT_LT(m2[50].mean_error_to_truth, 0.5 * m2[0].mean_error_to_truth);
}

// Claim 2: "The large damping factor causes the iteration to converge at a local minimum."
// Does not hold as stated: the iteration does not settle at a minimum for any λ_r, and in
// the regime of the experiment λ_r only rescales the iteration count: λ_r = 0.3 after k sweeps
// matches λ_r = 0.1 after 3k sweeps to within a few percent. A larger λ_r looks worse at a
// fixed sweep count only because it has travelled further along the same path.
TEST(Section6, DampingRescalesTheIterationCountRatherThanChangingTheMinimum) {
  const auto slow = mean_trace(3, 0.1, 900);
  const auto fast = mean_trace(3, 0.3, 300);
  for (int k : {10, 30, 100, 300}) {
    EXPECT_NEAR(fast[k].mean_error_to_truth, slow[3 * k].mean_error_to_truth, 0.04 * slow[3 * k].mean_error_to_truth) << k;
    EXPECT_NEAR(fast[k].mean_error_to_input, slow[3 * k].mean_error_to_input, 0.04 * slow[3 * k].mean_error_to_input) << k;
  }
  // Still drifting at the end: no fixed point was reached with either damping.
  EXPECT_GT(slow[900].mean_error_to_input, slow[300].mean_error_to_input);
}

// Claim 3: "The acceleration and the angular acceleration are rapidly reduced at first 10 steps."
// Holds: the first 10 sweeps remove most of the angular acceleration and more than the next 90.
TEST(Section6, AccelerationFallsFastInTheFirstTenIterations) {
  const auto m3 = mean_trace(3, 0.1, 100);
  const double a0 = m3[0].mean_angular_acceleration, a10 = m3[10].mean_angular_acceleration,
               a100 = m3[100].mean_angular_acceleration;
  EXPECT_LT(a10, 0.35 * a0);
  EXPECT_GT(a0 - a10, a10 - a100);
  const double p0 = m3[0].mean_acceleration, p10 = m3[10].mean_acceleration;
  EXPECT_LT(p10, 0.15 * p0);  // λ_t = 0.5 makes the translational part faster still
}

// The Fig. 1 loop at the perturbation bound (ε_r = 0.1): every sample within the bound.
TEST(Section6, TheFairingLoopHonoursTheBoundOfTheExperiment) {
  for (std::uint64_t s = 1; s <= 5; ++s) {
    SyntheticMotionSpec spec;
    spec.seed = s;
    const auto motion = make_synthetic_motion(spec);
    FairingParams p;
    p.epsilon_r = 0.1;
    p.epsilon_t = 10.0;
    p.max_iterations = 2000;
    const auto r = fair(motion.noisy, p);
    EXPECT_LT(r.max_dist_r, 0.1);
    EXPECT_LT(r.max_deviation_t, 10.0);
  }
}

// Fig. 1's loop with ε at the perturbation bound (0.1 rad, 10 mm), positions and orientations
// together: m = 3 keeps no sweep at all, because its one-sided end stencils move the first
// position by more than 10 mm in the first sweep; m = 2 stops within a few dozen sweeps, as soon
// as the noisiest sample's correction reaches the bound. The rotation bound alone allows more.
TEST(Section6, AtThePerturbationBoundTheLoopStopsEarly) {
  FairingParams p;
  p.max_iterations = 100000;
  p.epsilon_r = 0.1;
  p.epsilon_t = 10.0;
  p.order = 3;
  for (const auto& r : bounded_runs(SyntheticMotionSpec{}, 5, p)) {
    EXPECT_EQ(r.stop, StopReason::Bound);
    EXPECT_EQ(r.iterations, 0);
    EXPECT_GT(r.breaking_position, 0);
    EXPECT_TRUE(r.first_breaking == 0 || r.first_breaking == 99) << r.first_breaking;
  }
  p.order = 2;
  const auto both = bounded_runs(SyntheticMotionSpec{}, 5, p);
  p.epsilon_t = std::numeric_limits<double>::infinity();
  const auto rotation_m2 = bounded_runs(SyntheticMotionSpec{}, 5, p);
  p.order = 3;
  const auto rotation_m3 = bounded_runs(SyntheticMotionSpec{}, 5, p);
  for (std::size_t s = 0; s < 5; ++s) {
    EXPECT_LT(both[s].iterations, 40);
    EXPECT_LT(both[s].iterations, rotation_m2[s].iterations);
    EXPECT_GT(rotation_m3[s].iterations, 10);
    EXPECT_LT(rotation_m3[s].iterations, rotation_m2[s].iterations);
    EXPECT_EQ(rotation_m3[s].breaking_position, 0);
  }
}

// Claim (a) depends on how curved the motion is (Section 6's motion, 1 cycle, is the test above).
// Mean error to the input, seeds 1..3: on gentle motion (0.25 cycles) even m = 2, the order that
// drifts, stays inside the perturbation bound after 1000 sweeps; on fast motion (4 cycles) m = 2
// has left it after 100 sweeps and m = 3 after 400 (0.15; docs/fairing.md: 0.285 after 1000).
double mean_error_after(int order, double cycles, int sweeps) {
  double e = 0.0;
  for (std::uint64_t s = 1; s <= 3; ++s) {
    SyntheticMotionSpec spec;
    spec.seed = s;
    spec.cycles = cycles;
    spec.with_position = false;
    const auto motion = make_synthetic_motion(spec);
    FairingParams p;
    p.order = order;
    p.max_iterations = sweeps;
    const auto r = fair(motion.noisy, p);
    for (std::size_t i = 0; i < motion.noisy.size(); ++i)
      e += so3::dist(motion.noisy.orientation[i], r.poses.orientation[i]) / (3.0 * static_cast<double>(motion.noisy.size()));
  }
  return e;
}

TEST(Section6, ClaimAHoldsOnlyForModeratelyCurvedMotion) {
  const double gentle_m2 = mean_error_after(2, 0.25, 1000);
  EXPECT_LT(gentle_m2, 0.1);
  const double fast_m2 = mean_error_after(2, 4.0, 100);
  EXPECT_GT(fast_m2, 0.1);
  EXPECT_GT(mean_error_after(3, 4.0, 400), 0.1);
  // m = 2 drifts further the more curved the motion, even in a tenth of the sweeps.
  EXPECT_GT(fast_m2, 2.0 * gentle_m2);
}

// The paper's own setup for Figs. 4–8: perturbations within 0.2 rad and 20 mm.
SyntheticMotionSpec figures_4_to_8_spec() {
  SyntheticMotionSpec spec;
  spec.rotation_noise = 0.2;
  spec.position_noise = 20.0;
  return spec;
}

// Claim (c) on that setup.
TEST(Section6, AccelerationFallsFastOnTheSetupOfFigures4To8) {
  const SyntheticMotionSpec spec = figures_4_to_8_spec();
  FairingParams p;
  p.max_iterations = 100;
  const auto m3 = posefair::mean_trace(spec, 5, p);
  const double a0 = m3[0].mean_angular_acceleration, a10 = m3[10].mean_angular_acceleration,
               a100 = m3[100].mean_angular_acceleration;
  EXPECT_LT(a10, 0.35 * a0);
  EXPECT_GT(a0 - a10, a10 - a100);
  EXPECT_LT(m3[10].mean_acceleration, 0.15 * m3[0].mean_acceleration);
}

// Figures 6–8: translational fairing smooths the path and leaves the orientations as measured;
// the final motion is also smoother in rotation.
TEST(Section6, TheMotionsOfFigures6To8) {
  const SyntheticMotionSpec spec = figures_4_to_8_spec();
  FairingParams p;
  p.max_iterations = 100;
  const auto st = faired_motion_stages(spec, p);
  EXPECT_EQ(st.translation_faired.orientation, st.noisy.orientation);
  EXPECT_EQ(st.translation_faired.position, st.faired.position);
  EXPECT_LT(translational_energy(st.translation_faired.position, 3), 0.01 * translational_energy(st.noisy.position, 3));
  EXPECT_LT(mean_angular_acceleration(st.faired), 0.2 * mean_angular_acceleration(st.noisy));
}

}  // namespace
}  // namespace posefair
