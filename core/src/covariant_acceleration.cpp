#include "posefair/core/covariant_acceleration.hpp"

namespace posefair {

double covariant_acceleration_squared(const Vec4& q, const Vec4& q2) {
  const double a = q.dot(q2), b = q.squaredNorm();
  return q2.squaredNorm() - a * a / b;
}

IntegrandPartials objective_integrand(const Vec4& q, const Vec4& q2, double alpha) {
  const double a = q.dot(q2), b = q.squaredNorm();
  const double T = a / b;
  const double unit_gap = 1.0 - b;
  IntegrandPartials p;
  p.value = q2.squaredNorm() - a * T + alpha * unit_gap * unit_gap;
  // ∂/∂q of −a²/b is −2T q″ + 2T² q; of α(1 − b)² it is −4α(1 − b) q. Together 2(U + W).
  p.d_q = 2.0 * (T * T * q - T * q2) - 4.0 * alpha * unit_gap * q;
  // ∂/∂q″ of |q″|² − a²/b is 2(q″ − T q) = 2V.
  p.d_q2 = 2.0 * (q2 - T * q);
  return p;
}

Vec4 euler_lagrange_vector(const CurveJet& j, double alpha) {
  // d_ij = q^(i) · q^(j)
  const double d00 = j.q.dot(j.q), d01 = j.q.dot(j.d1), d02 = j.q.dot(j.d2), d03 = j.q.dot(j.d3),
               d04 = j.q.dot(j.d4), d11 = j.d1.dot(j.d1), d12 = j.d1.dot(j.d2), d13 = j.d1.dot(j.d3),
               d22 = j.d2.dot(j.d2);
  const double b = d00, T = d02 / d00;
  const double T1 = (d12 + d03) / d00 - 2.0 * d01 * d02 / (d00 * d00);
  // Eq. 8 (t1 + t2 + t3) plus the q·q⁗ term the paper drops for cubics.
  const double t1 = (2.0 * d13 + d22 + d04) / d00 - 4.0 * d01 * (d12 + d03) / (d00 * d00);
  const double t2 = -2.0 * d02 * (d02 + d11) / (d00 * d00);
  const double t3 = 8.0 * d01 * d01 * d02 / (d00 * d00 * d00);
  const double T2 = t1 + t2 + t3;
  const Vec4 U = j.q * T * T - j.d2 * T;
  const Vec4 V2 = j.d4 - (j.d2 * T + 2.0 * j.d1 * T1 + j.q * T2);
  const Vec4 W = 2.0 * alpha * (b - 1.0) * j.q;
  return 2.0 * (U + V2 + W);
}

}  // namespace posefair
