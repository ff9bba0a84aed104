#pragma once
// Lee & Shin's forward difference operators and the energies built from them.
//   D^m p_i: ordinary m-th forward difference of positions (eq. 8).
//   W^m q_i: W^1 q_i = log(q_i⁻¹ q_{i+1}), then ordinary differences of that sequence (eq. 10).
// Both are defined for i = 0 … n-1-m (ERRATA item 2), so they return n-m values.
// W^m uses eq. 10's sign: W² q_i = log(q_{i+1}⁻¹ q_{i+2}) − log(q_i⁻¹ q_{i+1}) (ERRATA item 1).
#include <span>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair {

// Throws std::invalid_argument if m < 1 or the sequence has fewer than m+1 samples.
std::vector<Vec3> position_differences(std::span<const Vec3> p, int m);
std::vector<Vec3> orientation_differences(std::span<const Quat> q, int m);

// E_m^t = Σ ‖D^m p_i‖² and E_m^r = Σ ‖W^m q_i‖² over i = 0 … n-1-m (eq. 12).
double translational_energy(std::span<const Vec3> p, int m);
double rotational_energy(std::span<const Quat> q, int m);

// In place, on the first len entries of v (no allocation, for the real-time window):
// v -> D v (len-1 entries, the forward difference), and v -> Dᵀ v (len+1 entries, its adjoint).
inline void forward_difference_in_place(std::span<Vec3> v, int len) {
  for (int i = 0; i + 1 < len; ++i) v[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i + 1)] - v[static_cast<std::size_t>(i)];
}
inline void difference_adjoint_in_place(std::span<Vec3> v, int len) {
  for (int i = len; i >= 0; --i) {
    const Vec3 prev = i > 0 ? v[static_cast<std::size_t>(i - 1)] : Vec3::Zero();
    const Vec3 here = i < len ? v[static_cast<std::size_t>(i)] : Vec3::Zero();
    v[static_cast<std::size_t>(i)] = prev - here;
  }
}

}  // namespace posefair
