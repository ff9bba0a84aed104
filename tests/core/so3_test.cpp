#include "posefair/core/so3.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "posefair/core/quaternion_lanes.hpp"
#include "test_sequences.hpp"

namespace posefair {
namespace {

using testing::random_direction;
using testing::random_unit_quaternion;
constexpr double kPi = std::numbers::pi;

// Half-angles covering the whole valid range of log, with the numerically hard ends.
const double kAngles[] = {0.0, 1e-300, 1e-200, 1e-16, 1e-12, 1e-9, 1e-8, 1e-6, 1e-5, 9.99e-5, 1e-4, 1.01e-4,
                          1e-3, 0.01, 0.1, 0.5, 1.0, 1.5, kPi / 2 - 1e-6, kPi / 2 - 1e-9, kPi / 2 - 1e-12, kPi / 2};

TEST(So3, ExpHasUnitNormAndHalfAngleConvention) {
  std::mt19937_64 rng(3);
  for (double a : kAngles) {
    const Vec3 axis = random_direction(rng);
    const Quat q = so3::exp(a * axis);
    ASSERT_FALSE(std::isnan(q.w()) || q.vec().hasNaN()) << a;
    EXPECT_NEAR(q.norm(), 1.0, 1e-15) << a;
    EXPECT_NEAR(q.w(), std::cos(a), 1e-15) << a;
    // The rotation angle of exp(v) is 2|v|: compare with Eigen's axis-angle.
    const Eigen::AngleAxisd ref(2.0 * a, axis);
    EXPECT_LT(so3::dist(q, Quat(ref)), 1e-14) << a;
  }
}

TEST(So3, LogInvertsExpOverTheWholeRange) {
  std::mt19937_64 rng(5);
  for (double a : kAngles) {
    for (int rep = 0; rep < 20; ++rep) {
      const Vec3 v = a * random_direction(rng);
      const Vec3 back = so3::log(so3::exp(v));
      ASSERT_FALSE(back.hasNaN()) << a;
      if (a < kPi / 2 - 1e-6) {
        EXPECT_LE((back - v).norm(), 1e-15 + 1e-14 * a) << "angle " << a;
      } else {
        // At |v| = pi/2 the hemisphere choice is ambiguous: v and -v are the same rotation.
        EXPECT_LT(so3::dist(so3::exp(back), so3::exp(v)), 1e-12) << a;
      }
    }
  }
}

TEST(So3, ExpInvertsLogForEveryUnitQuaternion) {
  std::mt19937_64 rng(7);
  for (int rep = 0; rep < 2000; ++rep) {
    Quat q = random_unit_quaternion(rng);
    const Vec3 v = so3::log(q);
    EXPECT_LE(v.norm(), kPi / 2 + 1e-15);
    const Quat back = so3::exp(v);
    EXPECT_LT(so3::dist(back, q), 1e-15);
    EXPECT_LT((back.coeffs() - so3::aligned_to(q, back).coeffs()).norm(), 1e-15);
  }
  // Near identity, near pi (w -> 0) and both hemispheres.
  for (double a : kAngles) {
    const Vec3 axis = random_direction(rng);
    for (double sign : {1.0, -1.0}) {
      const Quat q(sign * std::cos(a), sign * std::sin(a) * axis.x(), sign * std::sin(a) * axis.y(),
                   sign * std::sin(a) * axis.z());
      EXPECT_LT(so3::dist(so3::exp(so3::log(q)), q), 1e-15) << a;
    }
  }
}

TEST(So3, LogIgnoresNormAndSign) {
  const Quat q = so3::exp(Vec3(0.3, -0.2, 0.1));
  const Vec3 v = so3::log(q);
  EXPECT_LT((so3::log(Quat(-q.coeffs())) - v).norm(), 1e-15);
  EXPECT_LT((so3::log(Quat(3.0 * q.coeffs())) - v).norm(), 1e-15);
}

// Below 0.1 exp and log take series instead of sin, cos and atan2 (so3.cpp): they agree with the
// library's functions to a few units of rounding on either side of where the series end, and
// series a term shorter would not (the bounds' notes).
TEST(So3, SeriesAgreeWithTheLibraryFunctionsWhereTheyAreUsed) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double exp_worst = 0.0, log_worst = 0.0;
  for (int rep = 0; rep < 20000; ++rep) {
    // Half the draws in [0.05, 0.15], across the series' end; the rest log-uniform from 1e-8.
    const double a = rep % 2 == 0 ? 0.05 + 0.1 * unit(rng) : std::pow(10.0, -8.0 + 7.5 * unit(rng));
    const Vec3 axis = random_direction(rng);
    const Quat q = so3::exp(a * axis);
    const Quat reference(std::cos(a), std::sin(a) * axis.x(), std::sin(a) * axis.y(), std::sin(a) * axis.z());
    exp_worst = std::max(exp_worst, (q.coeffs() - reference.coeffs()).norm());
    // log of a quaternion of any norm: the vector part's direction times atan2(|v|, w).
    const double norm = 0.5 + 2.0 * unit(rng);
    const Quat r(norm * std::cos(a), norm * std::sin(a) * axis.x(), norm * std::sin(a) * axis.y(), norm * std::sin(a) * axis.z());
    const Vec3 expected = std::atan2(r.vec().norm(), r.w()) / r.vec().norm() * r.vec();
    log_worst = std::max(log_worst, (so3::log(r) - expected).norm() / expected.norm());
  }
  EXPECT_LT(exp_worst, 5e-16);  // (1.2e-16; without sinc's θ⁸ term 2.8e-15)
  EXPECT_LT(log_worst, 6e-16);  // (4.3e-16 relative; without the x¹⁴ term 9.1e-16)
}

TEST(So3, DistIsAccurateAtTinyAnglesAndAtTheFarEnd) {
  std::mt19937_64 rng(11);
  for (double a : {1e-12, 1e-9, 1e-7, 1e-4, 0.3, 1.2, kPi / 2 - 1e-9}) {
    const Quat q = random_unit_quaternion(rng);
    const Quat r = q * so3::exp(a * random_direction(rng));
    EXPECT_NEAR(so3::dist(q, r), a, 1e-15 + a * 1e-9) << a;
    EXPECT_NEAR(so3::dist(q, Quat(-r.coeffs())), a, 1e-15 + a * 1e-9) << "antipode " << a;
    EXPECT_NEAR(so3::rotation_angle(q, r), 2 * a, 2e-15 + a * 2e-9) << a;
  }
}

TEST(So3, SlerpFollowsTheShorterArc) {
  const Quat a = so3::exp(Vec3(0.1, 0.2, 0.0));
  const Quat b = so3::exp(Vec3(0.4, -0.1, 0.3));
  EXPECT_LT(so3::dist(so3::slerp(0.0, a, b), a), 1e-15);
  EXPECT_LT(so3::dist(so3::slerp(1.0, a, b), b), 1e-15);
  const Quat mid = so3::slerp(0.5, a, b);
  EXPECT_NEAR(so3::dist(a, mid), so3::dist(a, b) / 2, 1e-15);
  EXPECT_NEAR(so3::dist(mid, b), so3::dist(a, b) / 2, 1e-15);
  // -b is the same rotation: the path must be the same, not the long way round.
  const Quat mid_flipped = so3::slerp(0.5, a, Quat(-b.coeffs()));
  EXPECT_LT(so3::dist(mid_flipped, mid), 1e-15);
}

TEST(So3, RotationVectorConversionUsesThePhysicalAngle) {
  const Vec3 r(0.0, 0.0, kPi / 2);  // 90 degrees about z
  const Quat q = so3::from_rotation_vector(r);
  const Vec3 x_rotated = q * Vec3::UnitX();
  EXPECT_LT((x_rotated - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_LT((so3::to_rotation_vector(q) - r).norm(), 1e-15);
}

TEST(So3, MakeContinuousRemovesHemisphereFlipsWhateverTheInputSigns) {
  std::vector<Quat> base;
  for (int i = 0; i < 50; ++i) base.push_back(so3::exp(Vec3(0.05 * i, 0.02 * i, -0.03 * i)));
  std::vector<Quat> flipped = base;
  for (std::size_t i = 0; i < flipped.size(); i += 3) flipped[i].coeffs() = -flipped[i].coeffs();
  flipped[0].coeffs() = -flipped[0].coeffs();
  so3::make_continuous(base);
  so3::make_continuous(flipped);
  EXPECT_GE(base[0].w(), 0.0);
  for (std::size_t i = 0; i < base.size(); ++i) {
    EXPECT_EQ(base[i].coeffs(), flipped[i].coeffs()) << i;
    if (i > 0) {
      EXPECT_GE(base[i].dot(base[i - 1]), 0.0) << i;
    }
  }
}

// The batch sweep's branch-free exp and log (quaternion_lanes.hpp) against so3's, one at a time
// and kLaneWidth at a time, over the whole range of half-angles, both hemispheres.
TEST(So3, LaneExpAndLogAgreeWithSo3ToRounding) {
  using lanes::kLaneWidth;
  using lanes::Lane;
  std::mt19937_64 rng(17);
  std::vector<Vec3> v;
  for (double a : kAngles)
    for (int k = 0; k < 3; ++k) v.push_back(a * random_direction(rng));
  while (v.size() % kLaneWidth) v.push_back(Vec3::Zero());
  double worst_exp = 0.0, worst_log = 0.0;
  auto check = [&](std::size_t i, const lanes::QuatOf<double>& e, const lanes::VecOf<double>& l, const Quat& q) {
    const Quat ref = so3::exp(v[i]);
    worst_exp = std::max(worst_exp, (Quat(e.w, e.x, e.y, e.z).coeffs() - ref.coeffs()).cwiseAbs().maxCoeff());
    const Vec3 lr = so3::log(q);
    worst_log = std::max(worst_log, (Vec3(l.x, l.y, l.z) - lr).norm() / std::max(lr.norm(), 1e-300));
  };
  for (std::size_t i = 0; i < v.size(); i += kLaneWidth) {
    double vx[kLaneWidth], vy[kLaneWidth], vz[kLaneWidth], qw[kLaneWidth], qx[kLaneWidth], qy[kLaneWidth], qz[kLaneWidth];
    std::vector<Quat> q;
    for (int k = 0; k < kLaneWidth; ++k) {
      vx[k] = v[i + k].x(), vy[k] = v[i + k].y(), vz[k] = v[i + k].z();
      q.push_back(so3::exp(v[i + k]));
      if ((i + k) % 2) q.back().coeffs() = -q.back().coeffs();  // log must choose w >= 0
      qw[k] = q.back().w(), qx[k] = q.back().x(), qy[k] = q.back().y(), qz[k] = q.back().z();
    }
    const auto e = lanes::exp(lanes::VecOf<Lane>{lanes::load<Lane>(vx), lanes::load<Lane>(vy), lanes::load<Lane>(vz)});
    const auto l = lanes::log(lanes::QuatOf<Lane>{lanes::load<Lane>(qw), lanes::load<Lane>(qx), lanes::load<Lane>(qy),
                                                  lanes::load<Lane>(qz)});
    double ew[kLaneWidth], ex[kLaneWidth], ey[kLaneWidth], ez[kLaneWidth], lx[kLaneWidth], ly[kLaneWidth], lz[kLaneWidth];
    lanes::store(ew, e.w), lanes::store(ex, e.x), lanes::store(ey, e.y), lanes::store(ez, e.z);
    lanes::store(lx, l.x), lanes::store(ly, l.y), lanes::store(lz, l.z);
    for (int k = 0; k < kLaneWidth; ++k) {
      check(i + k, {ew[k], ex[k], ey[k], ez[k]}, {lx[k], ly[k], lz[k]}, q[k]);
      check(i + k, lanes::exp(lanes::VecOf<double>{vx[k], vy[k], vz[k]}),
            lanes::log(lanes::QuatOf<double>{qw[k], qx[k], qy[k], qz[k]}), q[k]);  // one at a time
    }
  }
  EXPECT_LT(worst_exp, 1e-15);
  EXPECT_LT(worst_log, 2e-15);
}

}  // namespace
}  // namespace posefair
