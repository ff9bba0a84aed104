#pragma once
// Ramamoorthi & Barr's objective (eq. 3 with ERRATA 1) over a whole Hermite curve,
//   OBJ = ∫ F(q, q″) dt,
// by Gauss–Legendre quadrature on every piece (the integrand is smooth inside a piece and may
// jump at nodes, so pieces are integrated separately), with its exact gradient with respect to
// every node's position and velocity.
#include <vector>

#include "posefair/core/gauss_legendre_rule.hpp"
#include "posefair/core/hermite_curve4.hpp"

namespace posefair {

struct ObjectiveGradient {
  std::vector<Vec4> d_position;  // ∂OBJ/∂p_i, one per node
  std::vector<Vec4> d_velocity;  // ∂OBJ/∂v_i
};

class SplineObjective {
 public:
  // alpha > 0 weighs the soft unit-norm term; quadrature_points per piece >= 1.
  SplineObjective(double alpha, int quadrature_points);

  double alpha() const { return alpha_; }
  double value(const HermiteCurve4& curve) const;
  // The value, and the gradient written into `gradient` (resized to the curve's nodes).
  double value_and_gradient(const HermiteCurve4& curve, ObjectiveGradient& gradient) const;
  // ∫ |q″ \ q|² dt alone (the covariant part, without the α term).
  double covariant_part(const HermiteCurve4& curve) const;

 private:
  double alpha_;
  QuadratureRule rule_;
};

}  // namespace posefair
