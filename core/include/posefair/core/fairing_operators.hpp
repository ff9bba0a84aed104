#pragma once
// Lee & Shin's fairing operators ρ_m (eqs. 16 and 18) and their damped forms (eq. 17),
// for m = 2 and m = 3, on positions and on unit quaternions.
//
// Each operator is a Jacobi step: every target q_i* is computed from the current sequence,
// then all samples move at once. The functions take caller-owned scratch spans and never
// allocate, so the sliding-window engine can call them per sample.
//
// Rotation variants (papers/ERRATA.md items 3 and 4; docs/fairing.md has the derivation):
//   Corrected (default): m = 2 interior is the geodesic midpoint slerp(½; q_{i-1}, q_{i+1});
//     m = 3 interior and i = n-2 use the "matched" slerp(2/3; q_i, q_i^printed). Both linearise
//     exactly to the translational rules.
//   Printed: the paper's formulas as printed (with eq. 15's sign fixed). Same fixed points;
//     m = 2 interior is over-relaxed by 2, m = 3 interior by 3/2.
// The end rules are exact solutions of W^m = 0 and are the same in both variants.
#include <span>

#include "posefair/core/so3.hpp"

namespace posefair {

enum class OperatorVariant { Corrected, Printed };

// Fewest samples an order-m operator is defined on (m = 2: 3, m = 3: 4).
// Throws std::invalid_argument for an order other than 2 or 3.
int min_samples_for_order(int m);

// The undamped operator: target[i] = p_i* for every i. Sizes: target.size() == p.size().
void position_targets(int m, std::span<const Vec3> p, std::span<Vec3> target);

// The undamped operator: target[i] = q_i*. u must hold q.size()-1 vectors (it receives
// u_j = log(q_j⁻¹ q_{j+1}), i.e. W^1). q must be hemisphere-continuous.
void rotation_targets(int m, OperatorVariant variant, std::span<const Quat> q, std::span<Vec3> u,
                      std::span<Quat> target);

// One damped sweep (eq. 17) in place: p_i <- λ p_i* + (1-λ) p_i.
void damped_position_sweep(int m, double lambda, std::span<Vec3> p, std::span<Vec3> target);

// One damped sweep (eq. 17) in place: q_i <- slerp(λ; q_i, q_i*) along the shorter arc,
// then renormalised (rounding only; ERRATA item 6).
void damped_rotation_sweep(int m, OperatorVariant variant, double lambda, std::span<Quat> q,
                           std::span<Vec3> u, std::span<Quat> target);

}  // namespace posefair
