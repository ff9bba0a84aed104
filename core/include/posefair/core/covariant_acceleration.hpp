#pragma once
// The integrand of Ramamoorthi & Barr's objective (eq. 3) and its Euler–Lagrange vector
// (eqs. 5–9), for paths q(t) in R⁴ that are only softly held on the unit sphere.
//
//   F(q, q″) = |q″|² − (q·q″)² / (q·q) + α (1 − q·q)²
//
// The first two terms are |q″ \ q|², the squared tangential (covariant) acceleration; the paper
// prints the denominator as q·q′, which is wrong (ERRATA 1): projecting q″ onto the tangent space
// of the sphere through q divides by |q|².
#include "posefair/core/hermite_curve4.hpp"

namespace posefair {

struct IntegrandPartials {
  double value = 0.0;
  Vec4 d_q = Vec4::Zero();   // ∂F/∂q
  Vec4 d_q2 = Vec4::Zero();  // ∂F/∂q″
};

// |q″ − (q·q″ / q·q) q|², the squared covariant acceleration (no α term). q must be non-zero.
double covariant_acceleration_squared(const Vec4& q, const Vec4& q2);

// F and its partial derivatives at one point (q non-zero).
IntegrandPartials objective_integrand(const Vec4& q, const Vec4& q2, double alpha);

// EL = ∂F/∂q − d/dt ∂F/∂q′ + d²/dt² ∂F/∂q″ = 2 (U + V″ + W) (eqs. 5–7), with
//   T = a/b, a = q·q″, b = q·q, U = qT² − q″T, V = q″ − qT, W = 2α(b − 1) q,
//   V″ = q⁗ − (q″T + 2q′T′ + qT″)   (eq. 6 with ERRATA 2: the last term is qT″, not qT‴),
// T′ and T″ analytic (eqs. 8–9, here keeping the q·q⁗ term so exact non-cubic paths work too).
// It vanishes on unit great circles traversed at constant speed.
Vec4 euler_lagrange_vector(const CurveJet& jet, double alpha);

}  // namespace posefair
