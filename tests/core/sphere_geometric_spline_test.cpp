// The algorithm on spheres (eq. 22 with eqs. 20-21): Theorem 4.3 (position, velocity and zero
// covariant acceleration at the ends), C^k across knots, the Figure 6 example (ERRATA item 3),
// unit norm to rounding, geodesic reproduction; S^2 and S^3.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "geometric_spline_test_support.hpp"
#include "posefair/core/sphere_geometric_spline.hpp"
#include "posefair/core/sphere_spline_figure6.hpp"

namespace posefair::geometric_splines {
namespace {

using testing::fd_tolerance;
using testing::kStep;

using P3 = SpherePoint<3>;

const Figure6Data kFig6 = figure6_data();
const P3 kFig6P0 = kFig6.p0, kFig6P1 = kFig6.p1, kFig6V0 = kFig6.v0;
const P3 kFig6V1Printed = kFig6.v1_printed, kFig6V1Corrected = kFig6.v1_corrected;

template <int D>
SpherePoint<D> tangential(const SpherePoint<D>& p, const SpherePoint<D>& x) {
  return x - p.dot(x) * p;
}

TEST(SphereGeometricSpline, Figure6DataAndErrataItem3) {
  EXPECT_NEAR(kFig6P0.norm(), 1.0, 1e-15);
  EXPECT_NEAR(kFig6P1.norm(), 1.0, 1e-15);
  EXPECT_NEAR(kFig6P0.dot(kFig6V0), 0.0, 1e-15);
  EXPECT_NEAR(kFig6P1.dot(kFig6V1Printed), 0.1, 1e-15);  // the printed v_{i+1} is not tangent
  EXPECT_NEAR(kFig6P1.dot(kFig6V1Corrected), 0.0, 1e-15);
  // The spline projects given velocities onto the tangent space.
  const SphereGeometricSpline<3> s({0.0, 1.0}, {kFig6P0, kFig6P1}, {kFig6V0, kFig6V1Printed}, 2);
  EXPECT_NEAR(s.velocities()[1].dot(kFig6P1), 0.0, 1e-15);
  EXPECT_LT((s.velocities()[1] - (kFig6V1Printed - 0.1 * kFig6P1)).norm(), 1e-15);
}

TEST(SphereGeometricSpline, Theorem43OnFigure6) {
  for (int k = 1; k <= 3; ++k) {
    const SmoothingFunction phi(k);
    auto s = [&](double u) { return sphere_segment<3>(phi, kFig6P0, kFig6V0, kFig6P1, kFig6V1Corrected, 1.0, u); };
    EXPECT_LT((s(0.0) - kFig6P0).norm(), 1e-15);
    EXPECT_LT((s(1.0) - kFig6P1).norm(), 1e-15);
    const double d = 1e-2;
    EXPECT_LT((testing::derivative(s, 0.0, 1, d) - kFig6V0).norm(), 1e-9) << k;
    EXPECT_LT((testing::derivative(s, 1.0, 1, d) - kFig6V1Corrected).norm(), 1e-9) << k;
    const P3 acc0 = testing::derivative(s, 0.0, 2, d), acc1 = testing::derivative(s, 1.0, 2, d);
    const double cov0 = tangential<3>(kFig6P0, acc0).norm(), cov1 = tangential<3>(kFig6P1, acc1).norm();
    if (k >= 2) {
      // Eq. 23: s'' = -|v|^2 p at the ends, so the covariant acceleration vanishes.
      EXPECT_LT((acc0 + kFig6V0.squaredNorm() * kFig6P0).norm(), 1e-7) << k;
      EXPECT_LT((acc1 + kFig6V1Corrected.squaredNorm() * kFig6P1).norm(), 1e-7) << k;
      EXPECT_LT(cov0, 1e-7) << k;
      EXPECT_LT(cov1, 1e-7) << k;
    } else {
      // phi(t) = t satisfies eq. 4 as printed for k = 1, yet the covariant acceleration at
      // the ends is far from zero: Theorem 4.3 needs phi'(0) = phi'(1) = 0, i.e. k >= 2.
      EXPECT_GT(cov0, 1.0);
      EXPECT_GT(cov1, 1.0);
    }
  }
}

TEST(SphereGeometricSpline, OrderThreeFollowsTheEndGeodesicsToThirdOrder) {
  // s''' = l''' = -|v|^2 v at u = 0 (the segment agrees with its end geodesic to order k).
  const SmoothingFunction phi(3);
  auto s = [&](double u) { return sphere_segment<3>(phi, kFig6P0, kFig6V0, kFig6P1, kFig6V1Corrected, 1.0, u); };
  EXPECT_LT((testing::derivative(s, 0.0, 3, 1e-2) + kFig6V0.squaredNorm() * kFig6V0).norm(), 1e-6);
  EXPECT_LT((testing::derivative(s, 1.0, 3, 1e-2) + kFig6V1Corrected.squaredNorm() * kFig6V1Corrected).norm(), 1e-6);
}

template <int D>
SphereGeometricSpline<D> random_sphere_spline(std::mt19937& rng, int count, int k) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> step(0.05, 0.4);
  std::vector<double> times;
  std::vector<SpherePoint<D>> points, velocities;
  SpherePoint<D> p;
  for (int i = 0; i < D; ++i) p[i] = n(rng);
  p.normalize();
  double t = 10.0;
  for (int i = 0; i < count; ++i) {
    SpherePoint<D> v;
    for (int j = 0; j < D; ++j) v[j] = n(rng);
    v = 1.5 * tangential<D>(p, v);  // about 1.5-3 rad/s
    times.push_back(t);
    points.push_back(p);
    velocities.push_back(v);
    const double h = step(rng);
    t += h;
    SpherePoint<D> jitter;
    for (int j = 0; j < D; ++j) jitter[j] = 0.2 * h * n(rng);
    p = sphere_geodesic<D>(p, v, h) + jitter;  // roughly where the motion goes, not exactly
    p.normalize();
  }
  return SphereGeometricSpline<D>(times, points, velocities, k);
}

template <int D>
void check_ck_across_knots(int k) {
  std::mt19937 rng(10 * D + k);
  const auto s = random_sphere_spline<D>(rng, 6, k);
  for (std::size_t i = 1; i + 1 < s.times().size(); ++i) {
    const double t = s.times()[i];
    // Steps in proportion to each segment's length (derivatives in t scale as 1/h^j).
    const double dl = kStep * (t - s.times()[i - 1]), dr = kStep * (s.times()[i + 1] - t);
    auto left = [&](double x) { return s.evaluate_segment(i - 1, x); };
    auto right = [&](double x) { return s.evaluate_segment(i, x); };
    EXPECT_LT((left(t) - s.points()[i]).norm(), 1e-14);
    EXPECT_LT((right(t) - s.points()[i]).norm(), 1e-14);
    EXPECT_LT((testing::derivative(left, t, 1, dl) - s.velocities()[i]).norm(), 1e-9 * (1 + s.velocities()[i].norm()));
    EXPECT_LT((testing::derivative(right, t, 1, dr) - s.velocities()[i]).norm(), 1e-9 * (1 + s.velocities()[i].norm()));
    for (int j = 2; j <= k + 1; ++j) {
      const auto a = testing::derivative(left, t, j, dl), b = testing::derivative(right, t, j, dr);
      const double scale = 1 + std::max(a.norm(), b.norm());
      if (j <= k) {
        EXPECT_LT((a - b).norm(), fd_tolerance(j) * scale) << "D=" << D << " k=" << k << " j=" << j << " knot " << i;
      } else {
        EXPECT_GT((a - b).norm(), 1e-3 * scale) << "D=" << D << " k=" << k << " knot " << i;  // generic data: not C^{k+1}
      }
      if (j == 2 && k >= 2) {  // covariant acceleration zero at the knot (Theorem 4.3)
        EXPECT_LT(tangential<D>(s.points()[i], a).norm(), 1e-7 * scale);
      }
    }
  }
}

TEST(SphereGeometricSpline, CkAcrossNonUniformKnotsOnS2) {
  for (int k = 1; k <= 3; ++k) check_ck_across_knots<3>(k);
}

TEST(SphereGeometricSpline, CkAcrossNonUniformKnotsOnS3) {
  for (int k = 1; k <= 3; ++k) check_ck_across_knots<4>(k);
}

TEST(SphereGeometricSpline, StaysOnTheSphereToRounding) {
  std::mt19937 rng(20);
  for (int k = 1; k <= 4; ++k) {
    const auto s2 = random_sphere_spline<3>(rng, 8, k);
    const auto s3 = random_sphere_spline<4>(rng, 8, k);
    for (double x = 0.0; x <= 1.0; x += 1.0 / 512) {
      EXPECT_NEAR(s2.evaluate(s2.start_time() + x * (s2.end_time() - s2.start_time())).norm(), 1.0, 4e-15);
      EXPECT_NEAR(s3.evaluate(s3.start_time() + x * (s3.end_time() - s3.start_time())).norm(), 1.0, 4e-15);
    }
    const SmoothingFunction phi(k);
    for (double u = 0.0; u <= 1.0; u += 1.0 / 256)
      EXPECT_NEAR(sphere_segment<3>(phi, kFig6P0, kFig6V0, kFig6P1, kFig6V1Corrected, 1.0, u).norm(), 1.0, 4e-15);
  }
}

TEST(SphereGeometricSpline, ReproducesAGeodesicTraversedAtConstantSpeed) {
  const SpherePoint<4> p0 = SpherePoint<4>(1, 2, -1, 0.5).normalized();
  const SpherePoint<4> v = tangential<4>(p0, SpherePoint<4>(0.3, -0.2, 0.7, 1.0));
  std::vector<double> times{0.0, 0.3, 0.35, 1.1};
  std::vector<SpherePoint<4>> points, velocities;
  for (double t : times) {
    points.push_back(sphere_geodesic<4>(p0, v, t));
    velocities.push_back(testing::derivative([&](double x) { return sphere_geodesic<4>(p0, v, x); }, t, 1, 1e-3));
  }
  for (int k = 1; k <= 3; ++k) {
    const SphereGeometricSpline<4> s(times, points, velocities, k);
    for (double t = 0.0; t <= 1.1; t += 0.01) EXPECT_LT((s.evaluate(t) - sphere_geodesic<4>(p0, v, t)).norm(), 1e-12);
  }
}

TEST(SphereGeometricSpline, ArcAndLogAreInverse) {
  const P3 a = P3(1, 0.2, -0.3).normalized(), b = P3(0.1, 1, 0.4).normalized();
  const P3 x = sphere_log<3>(a, b);
  EXPECT_NEAR(a.dot(x), 0.0, 1e-15);
  EXPECT_NEAR(x.norm(), std::acos(a.dot(b)), 1e-14);
  EXPECT_LT((sphere_geodesic<3>(a, x, 1.0) - b).norm(), 1e-15);
  EXPECT_LT((sphere_arc<3>(a, b, 0.4) - sphere_geodesic<3>(a, x, 0.4)).norm(), 1e-15);
  EXPECT_LT((sphere_arc<3>(a, a, 0.7) - a).norm(), 1e-16);
  EXPECT_DOUBLE_EQ(sinc(1e-5), std::sin(1e-5) / 1e-5);
  EXPECT_DOUBLE_EQ(sinc(2e-3), std::sin(2e-3) / 2e-3);
}

}  // namespace
}  // namespace posefair::geometric_splines
