#pragma once
// Lee & Shin's FAIRING procedure (Fig. 1) on a whole sequence: damped fairing sweeps until a
// sweep would move some sample beyond its bound (eq. 20), the iteration cap, or convergence.
//
// ERRATA item 5: the printed loop returns the first iterate that breaks eq. 20. This one keeps
// the last iterate that satisfies it, so every output is within the bound of its input:
//   ‖p_i − p_i⁽⁰⁾‖ < ε_t   and   dist(q_i, q_i⁽⁰⁾) < ε_r   (dist = eq. 19, angle on S³).
#include <functional>
#include <limits>
#include <span>
#include <string_view>

#include "posefair/core/fairing_operators.hpp"
#include "posefair/core/pose_sequence.hpp"

namespace posefair {

struct FairingParams {
  int order = 3;                                            // m ∈ {2, 3}
  double lambda_t = 0.5;                                    // translational damping, 0 < λ_t ≤ 1
  double lambda_r = 0.1;                                    // rotational damping, 0 < λ_r ≤ 1
  double epsilon_t = std::numeric_limits<double>::infinity();  // position bound (input units)
  double epsilon_r = std::numeric_limits<double>::infinity();  // orientation bound, dist on S³ (rad)
  int max_iterations = 100;                                 // cap on sweeps, ≥ 0
  double step_tolerance = 0.0;  // stop when no sample moves more than this in a sweep (0: never)
  OperatorVariant variant = OperatorVariant::Corrected;
};

enum class StopReason { IterationCap, Bound, Converged };
std::string_view to_string(StopReason r);

struct FairingResult {
  PoseSequence poses;              // same times; orientation signs match the input's samples
  int iterations = 0;              // sweeps applied to the returned poses
  StopReason stop = StopReason::IterationCap;
  double rotational_energy_before = 0.0, rotational_energy_after = 0.0;        // E_m^r
  double translational_energy_before = 0.0, translational_energy_after = 0.0;  // E_m^t (0 without positions)
  double max_dist_r = 0.0;         // max_i dist(q_i, q_i⁽⁰⁾) on S³ (half the rotation angle)
  double max_deviation_t = 0.0;    // max_i ‖p_i − p_i⁽⁰⁾‖
};

// Called after every accepted sweep k = 1, 2, … with the current (hemisphere-continuous) state.
using FairingObserver =
    std::function<void(int iteration, std::span<const Quat> q, std::span<const Vec3> p)>;

// Throws std::invalid_argument for bad parameters, a sequence shorter than the order needs
// (m = 2: 3 samples, m = 3: 4), or positions whose count differs from the orientations'.
FairingResult fair(const PoseSequence& input, const FairingParams& params,
                   const FairingObserver& observer = {});

// Checks params; throws std::invalid_argument naming the parameter and the valid range.
void validate(const FairingParams& params);

}  // namespace posefair
