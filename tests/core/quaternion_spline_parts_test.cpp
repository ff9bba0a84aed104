// Building blocks of the quaternion spline: quadrature, Hermite pieces, the eq. 3 integrand and
// the Euler–Lagrange vector (eqs. 4–9 with ERRATA 1 and 2).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "posefair/core/covariant_acceleration.hpp"
#include "posefair/core/gauss_legendre_rule.hpp"
#include "posefair/core/hermite_curve4.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {
namespace {

Vec4 random_vec4(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec4(n(rng), n(rng), n(rng), n(rng));
}

Quat random_unit(std::mt19937& rng) {
  Vec4 v = random_vec4(rng).normalized();
  return Quat(v(0), v(1), v(2), v(3));
}

Vec4 as_vec4(const Quat& q) { return Vec4(q.w(), q.x(), q.y(), q.z()); }

TEST(GaussLegendreRule, IntegratesPolynomialsUpToDegreeTwoNMinusOneExactly) {
  for (int n = 1; n <= 10; ++n) {
    const QuadratureRule r = gauss_legendre_rule(n);
    for (int degree = 0; degree <= 2 * n; ++degree) {
      double sum = 0.0;
      for (int k = 0; k < n; ++k) sum += r.weight[k] * std::pow(r.node[k], degree);
      const double exact = 1.0 / (degree + 1);
      if (degree < 2 * n)
        EXPECT_NEAR(sum, exact, 1e-14) << "n " << n << " degree " << degree;
      else
        EXPECT_GT(std::abs(sum - exact), 5e-13) << "n " << n;  // not exact one degree higher
    }
  }
}

HermiteCurve4 random_curve(std::mt19937& rng, int nodes) {
  std::vector<HermiteNode> n(nodes);
  double t = 0.3;
  for (auto& x : n) {
    x.time = t;
    t += 0.5 + std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    x.position = random_vec4(rng);
    x.velocity = random_vec4(rng);
  }
  return HermiteCurve4(n);
}

TEST(HermiteCurve4, InterpolatesNodePositionsAndVelocities) {
  std::mt19937 rng(1);
  const HermiteCurve4 c = random_curve(rng, 5);
  for (std::size_t i = 0; i < c.nodes().size(); ++i) {
    // From the piece on the left and on the right of the node: C¹.
    for (std::size_t piece : {i == 0 ? std::size_t{0} : i - 1, std::min(i, c.pieces() - 1)}) {
      const double s = piece == i ? 0.0 : 1.0;
      const CurveJet j = c.jet_on_piece(piece, s);
      EXPECT_LT((j.q - c.nodes()[i].position).norm(), 1e-12);
      EXPECT_LT((j.d1 - c.nodes()[i].velocity).norm(), 1e-12);
    }
  }
}

TEST(HermiteCurve4, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(2);
  const HermiteCurve4 c = random_curve(rng, 3);
  const double t = c.nodes()[0].time + 0.37 * (c.nodes()[1].time - c.nodes()[0].time), h = 1e-5;
  const CurveJet j = c.jet(t), a = c.jet(t - h), b = c.jet(t + h);
  EXPECT_LT((j.d1 - (b.q - a.q) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((j.d2 - (b.d1 - a.d1) / (2 * h)).norm(), 1e-8);
  EXPECT_LT((j.d3 - (b.d2 - a.d2) / (2 * h)).norm(), 1e-8);
}

TEST(HermiteCurve4, SplittingAPieceLeavesTheCurveUnchanged) {
  std::mt19937 rng(3);
  HermiteCurve4 c = random_curve(rng, 4);
  const HermiteCurve4 before = c;
  const double t = 0.5 * (c.nodes()[1].time + c.nodes()[2].time) + 0.1;
  EXPECT_EQ(c.split_at(t), 2u);
  EXPECT_EQ(c.nodes().size(), 5u);
  for (double u = c.start_time(); u <= c.end_time(); u += 0.01) {
    EXPECT_LT((c.jet(u).q - before.jet(u).q).norm(), 1e-12);
    EXPECT_LT((c.jet(u).d2 - before.jet(u).d2).norm(), 1e-9);
  }
  EXPECT_THROW(c.split_at(c.nodes()[1].time), std::invalid_argument);
}

TEST(HermiteCurve4, RejectsTimesThatDoNotIncrease) {
  std::vector<HermiteNode> n(3);
  n[0].time = 0;
  n[1].time = 1;
  n[2].time = 1;
  EXPECT_THROW(HermiteCurve4{n}, std::invalid_argument);
  EXPECT_THROW(HermiteCurve4{std::vector<HermiteNode>(1)}, std::invalid_argument);
}

TEST(ObjectiveIntegrand, PartialsMatchFiniteDifferences) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec4 q = random_vec4(rng), q2 = random_vec4(rng);
    const double alpha = 37.0, h = 1e-6;
    const IntegrandPartials p = objective_integrand(q, q2, alpha);
    for (int i = 0; i < 4; ++i) {
      const Vec4 e = Vec4::Unit(i) * h;
      const double dq = (objective_integrand(q + e, q2, alpha).value - objective_integrand(q - e, q2, alpha).value) / (2 * h);
      const double dq2 = (objective_integrand(q, q2 + e, alpha).value - objective_integrand(q, q2 - e, alpha).value) / (2 * h);
      EXPECT_NEAR(p.d_q(i), dq, 1e-5 * (1.0 + std::abs(dq)));
      EXPECT_NEAR(p.d_q2(i), dq2, 1e-5 * (1.0 + std::abs(dq2)));
    }
  }
}

TEST(ObjectiveIntegrand, CovariantPartIsTheTangentialAccelerationSquared) {
  // ERRATA 1: the projection divides by q·q. On any circle through the origin's plane traversed
  // at unit rate, q″ = −q is purely normal, whatever |q| is; the printed q·q′ (= 0 there) would
  // divide by zero.
  std::mt19937 rng(5);
  for (double radius : {0.5, 1.0, 1.3}) {
    const Vec4 q = radius * random_vec4(rng).normalized();
    EXPECT_NEAR(covariant_acceleration_squared(q, -q), 0.0, 1e-12);
  }
  const Vec4 q = random_vec4(rng), a = random_vec4(rng);
  const Vec4 tangential = a - (a.dot(q) / q.squaredNorm()) * q;
  EXPECT_NEAR(covariant_acceleration_squared(q, a), tangential.squaredNorm(), 1e-12);
  const double alpha = 10.0;
  EXPECT_NEAR(objective_integrand(q, a, alpha).value,
              tangential.squaredNorm() + alpha * std::pow(1.0 - q.squaredNorm(), 2), 1e-10);
}

// q(t) = l · (cos ωt, sin ωt, 0, 0) · r: a unit great circle at constant speed ω, in a random
// plane of R⁴ (left and right multiplication by unit quaternions are rotations of R⁴).
CurveJet great_circle(const Quat& l, const Quat& r, double omega, double t) {
  const double c = std::cos(omega * t), s = std::sin(omega * t);
  auto at = [&](double w, double x) { return as_vec4(l * Quat(w, x, 0, 0) * r); };
  CurveJet j;
  j.q = at(c, s);
  j.d1 = at(-omega * s, omega * c);
  j.d2 = at(-omega * omega * c, -omega * omega * s);
  j.d3 = at(std::pow(omega, 3) * s, -std::pow(omega, 3) * c);
  j.d4 = at(std::pow(omega, 4) * c, std::pow(omega, 4) * s);
  return j;
}

TEST(EulerLagrange, VanishesOnGreatCircles) {
  std::mt19937 rng(6);
  for (int trial = 0; trial < 20; ++trial) {
    const Quat l = random_unit(rng), r = random_unit(rng);
    const double omega = 0.3 + trial * 0.2;
    for (double t : {-1.0, 0.0, 0.4, 2.5}) {
      const CurveJet j = great_circle(l, r, omega, t);
      EXPECT_LT(euler_lagrange_vector(j, 1000.0).norm(), 1e-9 * (1 + std::pow(omega, 4))) << trial;
    }
  }
}

TEST(EulerLagrange, DoesNotVanishOffGreatCircles) {
  // A small circle on the unit sphere, (cos φ cos t, cos φ sin t, sin φ, 0): unit norm, constant
  // speed, but its acceleration has a tangential part, so it is not optimal.
  const double phi = 0.4;
  CurveJet j;
  const double t = 0.7, c = std::cos(t), s = std::sin(t), cp = std::cos(phi);
  j.q = Vec4(cp * c, cp * s, std::sin(phi), 0);
  j.d1 = Vec4(-cp * s, cp * c, 0, 0);
  j.d2 = Vec4(-cp * c, -cp * s, 0, 0);
  j.d3 = Vec4(cp * s, -cp * c, 0, 0);
  j.d4 = Vec4(cp * c, cp * s, 0, 0);
  EXPECT_GT(euler_lagrange_vector(j, 1000.0).norm(), 0.1);
  // And a great circle of radius 1.01 is pushed back to the sphere by the α term: EL = 4α(b−1)q.
  const CurveJet g = great_circle(Quat::Identity(), Quat::Identity(), 1.0, 0.3);
  CurveJet big = g;
  big.q *= 1.01, big.d1 *= 1.01, big.d2 *= 1.01, big.d3 *= 1.01, big.d4 *= 1.01;
  const double alpha = 1000.0;
  EXPECT_LT((euler_lagrange_vector(big, alpha) - 4 * alpha * (1.01 * 1.01 - 1) * big.q).norm(), 1e-9);
}

TEST(EulerLagrange, MatchesNumericalDifferentiationOnACubic) {
  // EL = ∂F/∂q + d²/dt² ∂F/∂q″ with the second derivative taken numerically along a cubic
  // piece: checks T′, T″ of eqs. 8–9 and the qT″ of eq. 6 (ERRATA 2).
  std::mt19937 rng(7);
  const HermiteCurve4 c = random_curve(rng, 2);
  const double alpha = 50.0, h = 1e-4;
  for (double s : {0.2, 0.5, 0.81}) {
    const double t = c.start_time() + s * (c.end_time() - c.start_time());
    auto dF_dq2 = [&](double u) {
      const CurveJet j = c.jet(u);
      return objective_integrand(j.q, j.d2, alpha).d_q2;
    };
    const CurveJet j = c.jet(t);
    const Vec4 numeric = objective_integrand(j.q, j.d2, alpha).d_q + (dF_dq2(t + h) - 2 * dF_dq2(t) + dF_dq2(t - h)) / (h * h);
    const Vec4 analytic = euler_lagrange_vector(j, alpha);
    EXPECT_LT((analytic - numeric).norm(), 1e-5 * (1 + analytic.norm())) << s;
  }
}

}  // namespace
}  // namespace posefair
