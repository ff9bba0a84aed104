#pragma once
// Per-iteration traces of the FAIRING loop on a synthetic sequence with known truth: the
// measurements behind Lee & Shin's Figures 2–5, the motions of Figures 6–8, and the loop of
// Fig. 1 run at a bound (docs/fairing.md reproduces them).
#include <cstddef>
#include <vector>

#include "posefair/core/fairing.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair {

struct FairingTracePoint {
  int iteration = 0;
  double mean_error_to_input = 0.0;   // Σ dist(q_i⁽⁰⁾, q_i⁽ᵏ⁾)/n, the paper's "average error" (rad on S³)
  double mean_error_to_truth = 0.0;   // Σ dist(truth_i, q_i⁽ᵏ⁾)/n
  double max_error_to_input = 0.0;    // max_i dist(q_i⁽⁰⁾, q_i⁽ᵏ⁾)
  double mean_angular_acceleration = 0.0;  // Σ‖W² q_i‖/(n-2)/Δ², physical rad/s² (×2 for half-angle)
  double mean_position_error_to_truth = 0.0;  // mm, 0 without positions
  double mean_acceleration = 0.0;     // Σ‖D² p_i‖/(n-2)/Δ², mm/s²
  double rotational_energy = 0.0;     // E_m^r
};

// Runs fair() with `params` on motion.noisy (ε bounds as given; set them infinite to watch the
// unbounded iteration) and returns iteration 0 (the input) and every accepted iteration.
std::vector<FairingTracePoint> trace_fairing(const SyntheticMotion& motion, const FairingParams& params);

// The trace averaged point by point over seeds 1 … seeds of `spec` (spec.seed is ignored).
std::vector<FairingTracePoint> mean_trace(const SyntheticMotionSpec& spec, int seeds, const FairingParams& params);

// Mean angular acceleration Σ 2‖W² q_i‖/(n−2)/Δ² in physical rad/s² (Δ from the first two times):
// how curved a motion is, and what Figures 4–5 plot.
double mean_angular_acceleration(const PoseSequence& poses);

// Fig. 1's loop as `params` set it, on seeds 1 … seeds of `spec`: how many sweeps it keeps, why
// it stopped, and for a bound stop which samples the next sweep would have moved too far.
struct BoundedRun {
  int seed = 0;
  int iterations = 0;
  StopReason stop = StopReason::IterationCap;
  int breaking_rotation = 0;   // samples whose next iterate breaks ε_r
  int breaking_position = 0;   // … breaks ε_t
  std::ptrdiff_t first_breaking = -1;  // the lowest such sample index (−1: none)
};
std::vector<BoundedRun> bounded_runs(const SyntheticMotionSpec& spec, int seeds, const FairingParams& params);

// Figures 6–8: the noisy motion, the motion after fairing positions only (orientations as
// measured), and after fairing both, each with `params` (its bounds as given).
struct FairedMotionStages {
  PoseSequence truth, noisy, translation_faired, faired;
};
FairedMotionStages faired_motion_stages(const SyntheticMotionSpec& spec, const FairingParams& params);

}  // namespace posefair
