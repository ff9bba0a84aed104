// Mahony, Hamel & Pflimlin 2008, the explicit complementary filter, written from the paper:
// omega_mes = sum_i k_i v_i × v̂_i over the measured directions v_i and their estimates
// v̂_i = R^T v0_i (gravity, and the field reduced to its north-up plane as the heading
// reference); the gyroscope is corrected by kp·omega_mes plus the integral ki·∫omega_mes.
#include "posefair/core/mahony_estimator.hpp"

namespace posefair {

namespace {

class MahonyEstimator final : public OrientationEstimator {
 public:
  MahonyEstimator(double kp, double ki, const EstimatorLimits& limits)
      : OrientationEstimator(limits), kp_(kp), ki_(ki) {}
  std::string_view name() const override { return "mahony"; }

 private:
  void step(const ImuStep& in) override {
    Vec3 omega = in.gyro != nullptr ? *in.gyro : Vec3::Zero();
    if (in.accel != nullptr) {
      Vec3 error = in.accel->normalized().cross(q_.conjugate() * Vec3::UnitZ());
      if (in.mag != nullptr) {
        const Vec3 m = in.mag->normalized();
        const Vec3 h = q_ * m;
        const Vec3 b(0.0, std::hypot(h.x(), h.y()), h.z());
        error += m.cross(q_.conjugate() * b);
      }
      if (ki_ > 0.0 && !in.gyro_saturated) integral_ += ki_ * error * in.dt;
      omega += kp_ * error + integral_;
    }
    state_.gyro_bias = -integral_;
    Quat next;
    next.coeffs() = q_.coeffs() + 0.5 * (q_ * Quat(0.0, omega.x(), omega.y(), omega.z())).coeffs() * in.dt;
    q_ = next.normalized();
  }

  double kp_, ki_;
  Vec3 integral_ = Vec3::Zero();
};

constexpr auto kMahonyOptions = with_common_estimator_options(std::array<OptionSpec, 2>{{
    {"kp", OptionType::Float, "0.74", "proportional gain, rad/s (BROAD's TAGP)"},
    {"ki", OptionType::Float, "0.0012", "integral gain, rad/s² (BROAD's TAGP)"},
}});

std::unique_ptr<OrientationEstimator> make_mahony_from_options(const OptionMap& options) {
  const OptionReader r(kMahonyOptions, options);
  const double kp = r.real("kp"), ki = r.real("ki");
  if (!(kp >= 0.0)) throw OptionError("kp", "must be zero or positive");
  if (!(ki >= 0.0)) throw OptionError("ki", "must be zero or positive");
  return std::make_unique<MahonyEstimator>(kp, ki, read_estimator_limits(r));
}

}  // namespace

const OrientationEstimatorEntry kMahonyEstimator{
    "mahony", "Mahony's explicit complementary filter (baseline)", kMahonyOptions, make_mahony_from_options};

}  // namespace posefair
