#pragma once
// Per-iteration traces of the FAIRING loop on a synthetic sequence with known truth: the
// measurements behind Lee & Shin's Figures 2–5 (docs/fairing.md reproduces them).
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

}  // namespace posefair
