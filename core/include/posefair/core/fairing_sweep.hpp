#pragma once
// One sweep of the batch FAIRING loop (Lee & Shin, Fig. 1) on structure-of-arrays data, for fair().
//
// The same mathematics as damped_rotation_sweep / damped_position_sweep followed by the eq. 20
// check, arranged for speed: quaternions and positions are held as arrays of components; W¹ is
// one pass, and every interior sample's target, damping, renormalisation, bound check and
// movement are one fused pass over kLaneWidth samples at a time (quaternion_lanes.hpp:
// polynomial exp/log, no branches, no library calls, no allocation). Two algebraic identities
// remove work: for m = 3 the corrected target and the damping are slerps from the same q_i,
// so slerp(λ; q_i, slerp(⅔; q_i, P)) = q_i exp(⅔λ log(q_i⁻¹ P)); for m = 2 the geodesic
// midpoint slerp(½; a, b) is (a + b)/|a + b| (b on a's side). The end samples (2 or 3) use the
// operators' own scalar code.
//
// Orientations agree with the operators to rounding, not bit for bit (exp and log are
// polynomials, and the fused forms round differently): largest component difference 3e-16
// after one sweep, 1.4e-15 after 100, 1.3e-14 after 1000 (300 samples, 5 seeds, every order and
// variant); tests/core/fairing_test.cpp holds them to 1e-12. Positions are bit for bit. The bound check is exact: lanes compare squared chords against a
// margin of 1e-9 around tan²(ε_r/2), and any sample inside the margin is judged by so3::dist.
#include <span>
#include <vector>

#include "posefair/core/fairing.hpp"

namespace posefair {

// Components of a sequence of quaternions (w, x, y, z) or positions (x, y, z), one array each.
struct QuaternionArrays {
  std::vector<double> w, x, y, z;
  void assign(std::span<const Quat> q);
  Quat at(std::size_t i) const { return Quat(w[i], x[i], y[i], z[i]); }
  std::size_t size() const { return w.size(); }
};
struct PositionArrays {
  std::vector<double> x, y, z;
  void assign(std::span<const Vec3> p);
  Vec3 at(std::size_t i) const { return Vec3(x[i], y[i], z[i]); }
  std::size_t size() const { return x.size(); }
};

struct SweepOutcome {
  bool within = true;  // eq. 20 holds for every sample of the candidate
  bool moved = false;  // some sample of the candidate differs from the current iterate
};

class FairingSweep {
 public:
  // q0: unit, hemisphere-continuous measurements; p0: empty or one position per orientation.
  // params must be valid (validate()) and the sequence long enough for the order.
  FairingSweep(const FairingParams& params, std::span<const Quat> q0, std::span<const Vec3> p0);

  // Computes the candidate, one damped sweep of the current iterate, and checks it.
  SweepOutcome sweep();
  // The largest movement from the current iterate to the candidate: max of dist(q_i, q_i') and
  // ‖p_i − p_i'‖, computed exactly as fair() always has (scalar; only for a step tolerance).
  double step() const;
  // The candidate becomes the current iterate.
  void accept();

  std::size_t size() const { return n_; }
  bool has_position() const { return with_p_; }
  // The current iterate as quaternions and positions (sizes are set here).
  void current(std::vector<Quat>& q, std::vector<Vec3>& p) const;

 private:
  template <int M, bool Corrected, bool WithP> SweepOutcome sweep_as();
  template <int M, bool Corrected> void rotation_ends();
  void position_ends();
  bool exact_bound_check() const;

  FairingParams params_;
  std::size_t n_;
  bool with_p_;
  double k_inside_, k_outside_;  // the lanes' margins around tan²(ε_r/2)
  QuaternionArrays q0_, q_, next_;
  PositionArrays p0_, p_, p_next_;
  std::vector<double> ux_, uy_, uz_;  // W¹ of the current iterate (m = 3)
};

}  // namespace posefair
