// Lee & Shin, Section 6, reproduced: 100 samples of a smooth orientation curve perturbed by
// random rotations with ‖δ‖ < 0.1 (positions in a 400 mm cube, ‖δ‖ < 10 mm), averaged over
// several seeds. docs/fairing.md shows the same traces as plots and says which claims hold.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace posefair
