// Madgwick 2010, written from the report: the objective functions f_g (eq. 25) and f_b
// (eq. 29) with their Jacobians J_g (eq. 26) and J_b (eq. 30), the gradient J^T f (eq. 34) and
// the fusion q̇ = ½ q ⊗ ω - β ∇f/|∇f| (eqs. 42-44), in the report's earth frame (x towards
// magnetic north, z up), turned into ENU at the edge.
//
// The report writes the diagonal terms of the rotation with |q| = 1 substituted
// (2(½ - q2² - q3²) rather than q1² + q2² - q3² - q4²). On the unit sphere that is the same
// function, but its gradient in R⁴ differs by a multiple of q, which changes |∇f| and so the
// size of the step: BROAD's published figures use the report's form, so this does too (the
// check against them is in docs/fusion.md).
//
// Madgwick's published C code (which BROAD runs) names the field reference's components _2bx,
// _2bz and uses them where the report has 2bx, 2bz, but sets them to bx, bz: its reference is
// half the field, so at the true orientation f_b = -m/2, not 0. The optimum heading is the same;
// the balance of field and gravity in the normalised step is not. c_code_field = true does the
// same, to reproduce BROAD's figures; the default is the report's.
#include "posefair/core/madgwick_estimator.hpp"

#include <cmath>

namespace posefair {

namespace {

// ENU = (x-north frame) turned +90° about z.
const Quat kEnuFromNorthWestUp(std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5));

class MadgwickEstimator final : public OrientationEstimator {
 public:
  MadgwickEstimator(double beta, double reference_scale, const EstimatorLimits& limits)
      : OrientationEstimator(limits), beta_(beta), reference_scale_(reference_scale) {}
  std::string_view name() const override { return "madgwick"; }

 private:
  void initialise(const Vec3& accel, const Vec3* mag) override {
    OrientationEstimator::initialise(accel, mag);
    q_nwu_ = kEnuFromNorthWestUp.conjugate() * q_;
  }

  void step(const ImuStep& in) override {
    // The report's q = (q1, q2, q3, q4) = (w, x, y, z).
    const double q1 = q_nwu_.w(), q2 = q_nwu_.x(), q3 = q_nwu_.y(), q4 = q_nwu_.z();
    Eigen::Vector4d rate = Eigen::Vector4d::Zero();  // (w, x, y, z)
    if (in.gyro != nullptr) {
      const Quat r = q_nwu_ * Quat(0.0, in.gyro->x(), in.gyro->y(), in.gyro->z());
      rate << 0.5 * r.w(), 0.5 * r.x(), 0.5 * r.y(), 0.5 * r.z();
    }
    if (in.accel != nullptr) {
      const Vec3 a = in.accel->normalized();
      const Vec3 fg(2 * (q2 * q4 - q1 * q3) - a.x(), 2 * (q1 * q2 + q3 * q4) - a.y(),
                    2 * (0.5 - q2 * q2 - q3 * q3) - a.z());
      Eigen::Matrix<double, 3, 4> jg;
      jg << -2 * q3, 2 * q4, -2 * q1, 2 * q2,  //
          2 * q2, 2 * q1, 2 * q4, 2 * q3,      //
          0, -4 * q2, -4 * q3, 0;
      Eigen::Vector4d gradient = jg.transpose() * fg;
      if (in.mag != nullptr) {
        const Vec3 m = in.mag->normalized();
        const Vec3 h = q_nwu_ * m;  // the field in the earth frame (eq. 45)
        const double bx = reference_scale_ * std::hypot(h.x(), h.y()), bz = reference_scale_ * h.z();  // eq. 46
        const Vec3 fb(2 * bx * (0.5 - q3 * q3 - q4 * q4) + 2 * bz * (q2 * q4 - q1 * q3) - m.x(),
                      2 * bx * (q2 * q3 - q1 * q4) + 2 * bz * (q1 * q2 + q3 * q4) - m.y(),
                      2 * bx * (q1 * q3 + q2 * q4) + 2 * bz * (0.5 - q2 * q2 - q3 * q3) - m.z());
        Eigen::Matrix<double, 3, 4> jb;
        jb << -2 * bz * q3, 2 * bz * q4, -4 * bx * q3 - 2 * bz * q1, -4 * bx * q4 + 2 * bz * q2,  //
            -2 * bx * q4 + 2 * bz * q2, 2 * bx * q3 + 2 * bz * q1, 2 * bx * q2 + 2 * bz * q4,
            -2 * bx * q1 + 2 * bz * q3,  //
            2 * bx * q3, 2 * bx * q4 - 4 * bz * q2, 2 * bx * q1 - 4 * bz * q3, 2 * bx * q2;
        gradient += jb.transpose() * fb;
      }
      const double n = gradient.norm();
      if (n > 0.0) rate -= beta_ * gradient / n;
    }
    const Eigen::Vector4d next = Eigen::Vector4d(q1, q2, q3, q4) + rate * in.dt;
    q_nwu_ = Quat(next[0], next[1], next[2], next[3]).normalized();
    q_ = kEnuFromNorthWestUp * q_nwu_;
  }

  double beta_, reference_scale_;
  Quat q_nwu_ = Quat::Identity();
};

constexpr auto kMadgwickOptions = with_common_estimator_options(std::array<OptionSpec, 2>{{
    {"beta", OptionType::Float, "0.12",
     "gain of the gradient step, rad/s (BROAD's best common value on its 39 trials)"},
    {"c_code_field", OptionType::Boolean, "false",
     "true: the field reference at half length, as Madgwick's published C code has it (and BROAD's figures)"},
}});

std::unique_ptr<OrientationEstimator> make_madgwick_from_options(const OptionMap& options) {
  const OptionReader r(kMadgwickOptions, options);
  const double beta = r.real("beta");
  if (!(beta >= 0.0)) throw OptionError("beta", "must be zero or positive");
  return std::make_unique<MadgwickEstimator>(beta, r.boolean("c_code_field") ? 0.5 : 1.0,
                                             read_estimator_limits(r));
}

}  // namespace

const OrientationEstimatorEntry kMadgwickEstimator{
    "madgwick", "Madgwick's gradient-descent filter (baseline)", kMadgwickOptions, make_madgwick_from_options};

}  // namespace posefair
