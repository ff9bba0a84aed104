#pragma once
// Comparing interpolants by what they are sampled to: the slerp chain through keyframes, and
// the discrete covariant-acceleration energy of any uniformly sampled unit-quaternion path,
//   E_Δ = Σ_k |a_k − (a_k·q_k) q_k|² Δt,   a_k = (q_{k+1} − 2 q_k + q_{k−1}) / Δt²,
// which tends to ∫ |q″ \ q|² dt for a C² path as Δt → 0. For a path whose velocity jumps (a
// slerp chain) it grows like 1/Δt: each corner contributes |Δq′|²/Δt.
#include <span>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair {

// The piecewise slerp through (key_times, keys) at each of `times` (clamped to the keys' span).
// key_times strictly increasing, at least two keys.
std::vector<Quat> slerp_chain(std::span<const double> key_times, std::span<const Quat> keys,
                              std::span<const double> times);

// E_Δ above for samples at uniform spacing dt (at least three samples; signs need not agree).
double sampled_covariant_energy(std::span<const Quat> samples, double dt);

// start, start + dt, ... up to and including end (within rounding).
std::vector<double> uniform_times(double start, double end, double dt);

}  // namespace posefair
