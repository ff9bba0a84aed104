// The algorithm on SO(3) (eq. 16): Theorem 4.1's boundary conditions, zero covariant
// acceleration at the ends for k >= 2 (Theorem 4.2 with k = 2, 3), C^k across knots,
// orthogonality to rounding, and agreement with the S^3 version through the double cover.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "geometric_spline_test_support.hpp"
#include "posefair/core/so3_geometric_spline.hpp"
#include "posefair/core/sphere_geometric_spline.hpp"

namespace posefair::geometric_splines {
namespace {

using testing::fd_tolerance;
using testing::kStep;

Eigen::Matrix3d hat(const Vec3& w) {
  Eigen::Matrix3d k;
  k << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return k;
}

Eigen::Matrix3d skew_part(const Eigen::Matrix3d& m) { return 0.5 * (m - m.transpose()); }

struct So3Data {
  std::vector<double> times;
  std::vector<Rotation> rotations;
  std::vector<Vec3> omegas;
};

So3Data random_data(std::mt19937& rng, int count) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> step(0.05, 0.5);
  So3Data d;
  Rotation r = rotation_exp(Vec3(n(rng), n(rng), n(rng)));
  double t = 3.0;
  for (int i = 0; i < count; ++i) {
    const Vec3 w(n(rng), n(rng), n(rng));  // up to about 3 rad/s: segments turn well below pi
    d.times.push_back(t);
    d.rotations.push_back(r);
    d.omegas.push_back(w);
    const double h = step(rng);
    t += h;
    r = rotation_exp(h * w + 0.3 * h * Vec3(n(rng), n(rng), n(rng))) * r;
  }
  return d;
}

TEST(So3GeometricSpline, ExpAndLogAreInverse) {
  for (const Vec3& w : {Vec3(0.3, -1.2, 0.7), Vec3(1e-9, 2e-9, 0.0), Vec3(0.0, 0.0, 3.1)}) {
    const Rotation r = rotation_exp(w);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-15);
    EXPECT_LT((rotation_log(r) - w).norm(), 1e-14 * (1 + w.norm()));
    EXPECT_LT((r - Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()).norm(), 1e-15);
  }
}

TEST(So3GeometricSpline, Theorems41And42BoundaryConditions) {
  std::mt19937 rng(7);
  const So3Data d = random_data(rng, 2);
  const double h = d.times[1] - d.times[0];
  for (int k = 1; k <= 3; ++k) {
    const SmoothingFunction phi(k);
    auto s = [&](double t) {
      return so3_segment(phi, d.rotations[0], d.omegas[0], d.rotations[1], d.omegas[1], h, (t - d.times[0]) / h);
    };
    const double dt = kStep * h;
    for (int end = 0; end < 2; ++end) {
      const double t = d.times[end];
      const Rotation p = s(t);
      EXPECT_LT((p - d.rotations[end]).norm(), 1e-14);
      // s' = V p (Theorem 4.1).
      const Eigen::Matrix3d v = testing::derivative(s, t, 1, dt);
      EXPECT_LT((v - hat(d.omegas[end]) * p).norm(), 1e-8) << k;
      // Covariant acceleration: the tangential part of s'' is skew(s'' s^T) s = Omega' s.
      const Eigen::Matrix3d a = testing::derivative(s, t, 2, dt);
      const double covariant = skew_part(a * p.transpose()).norm();
      if (k >= 2) {
        EXPECT_LT(covariant, 1e-6) << k;
      } else {
        EXPECT_GT(covariant, 1e-2) << k;  // C^1 only: Theorem 4.2 asks nothing more of k = 1
      }
      if (k >= 3) {
        // D^2 s'/dt^2 = Omega'' s = 0 as well: s, s', s'' being those of the end geodesic
        // e^{tV} p, this is s''' = V^3 p.
        const Eigen::Matrix3d w = hat(d.omegas[end]);
        const Eigen::Matrix3d expected = w * w * w * p;
        EXPECT_LT((testing::derivative(s, t, 3, dt) - expected).norm(), fd_tolerance(3) * (1 + expected.norm())) << k;
      }
    }
  }
}

TEST(So3GeometricSpline, CkAcrossNonUniformKnotsAndOrthogonal) {
  std::mt19937 rng(8);
  for (int k = 1; k <= 3; ++k) {
    const So3Data d = random_data(rng, 5);
    const So3GeometricSpline s(d.times, d.rotations, d.omegas, k);
    for (std::size_t i = 1; i + 1 < d.times.size(); ++i) {
      const double t = d.times[i];
      auto left = [&](double x) { return s.evaluate_segment(i - 1, x); };
      auto right = [&](double x) { return s.evaluate_segment(i, x); };
      const double dl = kStep * (t - d.times[i - 1]), dr = kStep * (d.times[i + 1] - t);
      EXPECT_LT((left(t) - right(t)).norm(), 1e-14);
      for (int j = 1; j <= k + 1; ++j) {
        const Eigen::Matrix3d a = testing::derivative(left, t, j, dl), b = testing::derivative(right, t, j, dr);
        const double scale = 1 + std::max(a.norm(), b.norm());
        if (j <= k) {
          EXPECT_LT((a - b).norm(), fd_tolerance(j) * scale) << "k=" << k << " j=" << j;
        } else {
          EXPECT_GT((a - b).norm(), 1e-3 * scale) << "k=" << k;  // generic data: not C^{k+1}
        }
      }
    }
    for (double x = 0.0; x <= 1.0; x += 1.0 / 256) {
      const Rotation r = s.evaluate(s.start_time() + x * (s.end_time() - s.start_time()));
      EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 4e-15);
      EXPECT_NEAR(r.determinant(), 1.0, 4e-15);
    }
  }
}

TEST(So3GeometricSpline, EqualsTheS3SplineThroughTheDoubleCover) {
  // On S^3 = SU(2) the great arcs are one-parameter subgroups, so eq. 22 on unit quaternions and
  // eq. 16 on SO(3) give the same rotations (velocity v = 1/2 (0, w) q).
  std::mt19937 rng(9);
  for (int k = 1; k <= 3; ++k) {
    const So3Data d = random_data(rng, 4);
    std::vector<SpherePoint<4>> q, v;
    Quat previous = Quat::Identity();
    for (std::size_t i = 0; i < d.times.size(); ++i) {
      const Quat qi = so3::aligned_to(Quat(d.rotations[i]), previous);
      previous = qi;
      q.push_back(qi.coeffs());
      v.push_back(0.5 * (Quat(0.0, d.omegas[i].x(), d.omegas[i].y(), d.omegas[i].z()) * qi).coeffs());
    }
    const So3GeometricSpline lie(d.times, d.rotations, d.omegas, k);
    const SphereGeometricSpline<4> sphere(d.times, q, v, k);
    for (double x = 0.0; x <= 1.0; x += 1.0 / 64) {
      const double t = lie.start_time() + x * (lie.end_time() - lie.start_time());
      const Quat qs(Eigen::Vector4d(sphere.evaluate(t)));
      EXPECT_LT((qs.toRotationMatrix() - lie.evaluate(t)).norm(), 1e-12) << k << " " << t;
    }
  }
}

}  // namespace
}  // namespace posefair::geometric_splines
