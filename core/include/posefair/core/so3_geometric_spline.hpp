#pragma once
// The three-step algorithm on the Lie group SO(3) (Rodrigues, Silva Leite & Jakubiak,
// Section 4.1, eq. 16) with the bi-invariant metric. Velocities are right-trivialised,
// v = V p with V = [w]x: w is the WORLD-frame angular velocity in rad/s (physical angle, not
// the half-angle of so3.hpp). On [t_i, t_{i+1}], u = (t - t_i)/h, V scaled by h (ERRATA 4):
//   l = e^{u V_i} p_i,  c = e^{u W} p_i (W = log(p_{i+1} p_i^T)),  r = e^{(u-1) V_{i+1}} p_{i+1}
//   a = e^{phi A} l (A = log(c l^T)),  b = e^{phi B} c (B = log(r c^T))
//   s = e^{phi S} a (S = log(b a^T)).
// Each log must stay below a rotation of pi (true when h|w| and the knot rotation are small).
#include <vector>

#include <Eigen/Core>

#include "posefair/core/so3.hpp"
#include "posefair/core/spline_smoothing_function.hpp"

namespace posefair::geometric_splines {

using Rotation = Eigen::Matrix3d;

// Rodrigues' formula: e^{[w]x} (rotation by |w| about w).
Rotation rotation_exp(const Vec3& w);
// Its inverse: the rotation vector (angle <= pi) of an orthogonal R.
Vec3 rotation_log(const Rotation& r);

// Eq. 16 on one segment (any u near [0, 1]).
Rotation so3_segment(const SmoothingFunction& phi, const Rotation& p0, const Vec3& w0, const Rotation& p1,
                     const Vec3& w1, double h, double u);

class So3GeometricSpline {
 public:
  // Throws std::invalid_argument: sizes differ, fewer than 2 knots, times not strictly increasing.
  So3GeometricSpline(std::vector<double> times, std::vector<Rotation> rotations, std::vector<Vec3> angular_velocities,
                     int order);

  double start_time() const { return times_.front(); }
  double end_time() const { return times_.back(); }
  Rotation evaluate(double t) const;  // std::out_of_range outside [start_time, end_time]
  Rotation evaluate_segment(std::size_t i, double t) const;

 private:
  std::vector<double> times_;
  std::vector<Rotation> rotations_;
  std::vector<Vec3> angular_velocities_;
  SmoothingFunction phi_;
};

}  // namespace posefair::geometric_splines
