// VQF, written from Laidig & Seel 2023 (vqf_estimator.hpp). Where the paper leaves a choice
// open, the comment says what is done here and why.
#include "posefair/core/vqf_estimator.hpp"

#include <algorithm>
#include <cmath>

#include "posefair/core/butterworth_lowpass.hpp"

namespace posefair {

namespace {

constexpr double kVqfDeg = M_PI / 180.0;

double wrap_heading(double a) {
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a < 0.0) a += 2.0 * M_PI;
  return a - M_PI;
}

class VqfEstimator final : public OrientationEstimator {
 public:
  VqfEstimator(const VqfParameters& p, const EstimatorLimits& limits)
      : OrientationEstimator(limits), p_(p) {
    const double s0 = p_.bias_sigma_init * kVqfDeg;
    p0_ = s0 * s0;
    covariance_ = Eigen::Matrix3d::Identity() * p0_;
  }
  std::string_view name() const override { return "vqf"; }

 private:
  // Coefficients depend on the sample time; they are recomputed when it changes by more than
  // 5 % (a jittery clock does not recompute every sample; a filter tolerates that much).
  void set_sample_time(double dt) {
    if (coefficient_dt_ > 0.0 && std::abs(dt - coefficient_dt_) <= 0.05 * coefficient_dt_) return;
    coefficient_dt_ = dt;
    acc_lp_.set_coefficients(p_.tau_acc, dt);
    motion_r_lp_.set_coefficients(p_.tau_acc, dt);
    motion_bias_lp_.set_coefficients(p_.tau_acc, dt);
    rest_gyr_lp_.set_coefficients(p_.rest_filter_tau, dt);
    rest_acc_lp_.set_coefficients(p_.rest_filter_tau, dt);
    mag_norm_dip_lp_.set_coefficients(p_.mag_current_tau, dt);
    k_mag_ = first_order_gain(p_.tau_mag, dt);
    k_mag_ref_ = first_order_gain(p_.mag_ref_tau, dt);
    // Bias Kalman filter: process noise such that the uncertainty grows from 0 to 0.1 deg/s in
    // bias_forgetting_time (the paper's definition of that parameter); measurement noise chosen so that a steady stream of
    // measurements converges to the standard deviation bias_sigma_{motion,rest}: the steady
    // state of P = (P + V) W / (P + V + W) at P = sigma^2 is W = sigma^2 (sigma^2 + V) / V.
    process_noise_ = std::pow(0.1 * kVqfDeg, 2) * dt / p_.bias_forgetting_time;
    const auto steady_w = [&](double sigma_deg) {
      const double s2 = std::pow(sigma_deg * kVqfDeg, 2);
      return s2 * (s2 + process_noise_) / process_noise_;
    };
    motion_w_ = steady_w(p_.bias_sigma_motion);
    vertical_w_ = motion_w_ / std::max(p_.bias_vertical_forgetting, 1e-10);
    rest_w_ = steady_w(p_.bias_sigma_rest);
  }

  void initialise(const Vec3& accel, const Vec3* mag) override {
    // Level at once from the first reading (the low-pass filter then starts from it); heading
    // from the first field reading, refined by the start-up gain below.
    q_gyr_ = Quat::Identity();
    q_acc_ = Quat::FromTwoVectors(accel.normalized(), Vec3::UnitZ()).normalized();
    delta_ = 0.0;
    if (mag != nullptr) {
      const Vec3 m = q_acc_ * *mag;
      if (std::hypot(m.x(), m.y()) > 1e-9 * m.norm()) delta_ = std::atan2(m.x(), m.y());
    }
    k_mag_init_ = 1.0;
    publish();
  }

  void after_gap() override {
    acc_lp_.reset();
    motion_r_lp_.reset();
    motion_bias_lp_.reset();
    rest_gyr_lp_.reset();
    rest_acc_lp_.reset();
    mag_norm_dip_lp_.reset();
    rest_time_ = 0.0;
    rest_ = false;
    k_mag_init_ = 1.0;
  }

  void step(const ImuStep& in) override {
    const double dt = in.dt;
    set_sample_time(dt);
    const bool gyro_ok = in.gyro != nullptr && !in.gyro_saturated;

    if (in.gyro != nullptr) {
      const Vec3& g = *in.gyro;
      const Vec3 lp = rest_gyr_lp_.step(g.array()).matrix();
      const double th = p_.rest_th_gyr * kVqfDeg;
      if (!gyro_ok || (g - lp).squaredNorm() >= th * th || lp.norm() > th) not_at_rest();
      q_gyr_ = (q_gyr_ * so3::from_rotation_vector((g - bias_) * dt)).normalized();
    } else {
      not_at_rest();
    }

    if (in.accel != nullptr) accel_step(*in.accel, dt, gyro_ok);
    if (in.mag != nullptr) mag_step(*in.mag, dt);
    publish();
  }

  void not_at_rest() {
    rest_time_ = 0.0;
    rest_ = false;
  }

  void accel_step(const Vec3& acc, double dt, bool gyro_ok) {
    const Vec3 lp = rest_acc_lp_.step(acc.array()).matrix();
    if ((acc - lp).squaredNorm() >= p_.rest_th_acc * p_.rest_th_acc || !gyro_ok) {
      not_at_rest();
    } else {
      rest_time_ += dt;
      rest_ = rest_time_ >= p_.rest_min_time;
    }

    // Low-pass in the almost-inertial frame I, then rotate by the inclination correction.
    const Vec3 acc_i_lp = acc_lp_.step((q_gyr_ * acc).array()).matrix();
    const Vec3 acc_e = (q_acc_ * acc_i_lp).normalized();
    const double qw = std::sqrt(std::max(0.0, (acc_e.z() + 1.0) / 2.0));
    const Quat correction = qw > 1e-6 ? Quat(qw, 0.5 * acc_e.y() / qw, -0.5 * acc_e.x() / qw, 0.0)
                                      : Quat(0.0, 1.0, 0.0, 0.0);  // upside down: turn over x
    q_acc_ = (correction * q_acc_).normalized();
    bias_step(acc_e, dt, gyro_ok);
  }

  void bias_step(const Vec3& acc_e, double dt, bool gyro_ok) {
    if (!p_.motion_bias && !p_.rest_bias) return;
    // The rotation and the bias it carries into the earth frame, low-passed like the
    // accelerometer, so the correction's implied rate compares like with like.
    const Eigen::Matrix3d r = (q_acc_ * q_gyr_).toRotationMatrix();
    // Zero until set (only read when motion_bias set them; GCC cannot see that).
    Eigen::Matrix3d r_lp = Eigen::Matrix3d::Zero();
    Eigen::Array2d bias_lp = Eigen::Array2d::Zero();
    if (p_.motion_bias) {
      Eigen::Array<double, 9, 1> flat = Eigen::Map<const Eigen::Array<double, 9, 1>>(r.data());
      Eigen::Map<Eigen::Array<double, 9, 1>>(r_lp.data()) = motion_r_lp_.step(flat);
      bias_lp = motion_bias_lp_.step(Eigen::Array2d(r.row(0).dot(bias_), r.row(1).dot(bias_)));
    }
    for (int i = 0; i < 3; ++i)
      if (covariance_(i, i) < p0_) covariance_(i, i) += process_noise_;

    Vec3 e;
    Eigen::Matrix3d h;
    Vec3 w;
    if (rest_ && p_.rest_bias) {
      e = rest_gyr_lp_.value().matrix() - bias_;
      h.setIdentity();
      w.setConstant(rest_w_);
    } else if (p_.motion_bias && gyro_ok && acc_lp_.ready() && motion_r_lp_.ready()) {
      // Only once the filters run: during their start-up (and after a gap) the correction
      // levels a fresh estimate at once, which is no measure of a drift.
      // The correction turned acc_e up by the rotation vector (a_y, -a_x, 0): at rate
      // ω = (a_y, -a_x)/dt in the earth frame, which cancels the drift R(b - b̂) of a bias error.
      e.x() = -acc_e.y() / dt + bias_lp[0] - r_lp.row(0).dot(bias_);
      e.y() = acc_e.x() / dt + bias_lp[1] - r_lp.row(1).dot(bias_);
      e.z() = -r_lp.row(2).dot(bias_);  // no vertical information: forget slowly towards zero
      h = r_lp;
      w = Vec3(motion_w_, motion_w_, vertical_w_);
    } else {
      return;
    }
    const Eigen::Matrix3d s = h * covariance_ * h.transpose() + Eigen::Matrix3d(w.asDiagonal());
    const Eigen::Matrix3d k = covariance_ * h.transpose() * s.inverse();
    bias_ += k * e;
    covariance_ -= k * h * covariance_;
    const double clip = p_.bias_clip * kVqfDeg;
    bias_ = bias_.cwiseMax(-clip).cwiseMin(clip);
  }

  void mag_step(const Vec3& mag, double dt) {
    const Vec3 m = (q_acc_ * q_gyr_) * mag;
    const double norm = m.norm();
    if (norm <= 0.0 || std::hypot(m.x(), m.y()) < 1e-9 * norm) return;
    const double dip = -std::asin(std::clamp(m.z() / norm, -1.0, 1.0));

    if (p_.mag_rejection) detect_disturbance(norm, dip, dt);

    double k = k_mag_;
    if (p_.mag_rejection) {
      if (disturbed_) {
        if (reject_time_ <= p_.mag_max_rejection_time) {
          reject_time_ += dt;
          k = 0.0;
        } else {
          k /= p_.mag_rejection_factor;  // a lasting disturbance: follow it, slowly
        }
      } else {
        reject_time_ = std::max(reject_time_ - p_.mag_rejection_factor * dt, 0.0);
      }
    }
    // Start-up: gains 1, 1/2, 1/3, ... (the mean of the readings so far) until they fall to k_mag.
    if (k_mag_init_ > 0.0) {
      k = std::max(k, k_mag_init_);
      k_mag_init_ = k_mag_init_ / (k_mag_init_ + 1.0);
      if (k_mag_init_ * p_.tau_mag < dt) k_mag_init_ = 0.0;
    }
    delta_ = wrap_heading(delta_ + k * wrap_heading(std::atan2(m.x(), m.y()) - delta_));
  }

  void detect_disturbance(double norm, double dip, double dt) {
    const Eigen::Array2d nd = mag_norm_dip_lp_.step(Eigen::Array2d(norm, dip));
    const double dip_th = p_.mag_dip_th * kVqfDeg;
    const auto agrees = [&](double ref_norm, double ref_dip) {
      return ref_norm > 0.0 && std::abs(nd[0] - ref_norm) < p_.mag_norm_th * ref_norm &&
             std::abs(nd[1] - ref_dip) < dip_th;
    };
    if (agrees(ref_norm_, ref_dip_)) {
      undisturbed_time_ += dt;
      if (undisturbed_time_ >= p_.mag_min_undisturbed_time) {
        disturbed_ = false;
        ref_norm_ += k_mag_ref_ * (nd[0] - ref_norm_);
        ref_dip_ += k_mag_ref_ * (nd[1] - ref_dip_);
      }
    } else {
      undisturbed_time_ = 0.0;
      disturbed_ = true;
    }
    // A new, steady field seen while the sensor turns becomes the reference (a disturbance
    // cannot stay steady in the sensor's frame and the earth's at once).
    if (agrees(candidate_norm_, candidate_dip_)) {
      if (rest_gyr_lp_.value().matrix().norm() >= p_.mag_new_min_gyr * kVqfDeg) {
        candidate_time_ += dt;
        candidate_norm_ += k_mag_ref_ * (nd[0] - candidate_norm_);
        candidate_dip_ += k_mag_ref_ * (nd[1] - candidate_dip_);
      }
      if (disturbed_ && (candidate_time_ >= p_.mag_new_time ||
                         (ref_norm_ == 0.0 && candidate_time_ >= p_.mag_new_first_time))) {
        ref_norm_ = candidate_norm_;
        ref_dip_ = candidate_dip_;
        disturbed_ = false;
        undisturbed_time_ = p_.mag_min_undisturbed_time;
      }
    } else {
      candidate_time_ = 0.0;
      candidate_norm_ = nd[0];
      candidate_dip_ = nd[1];
    }
  }

  void publish() {
    const Quat heading(Eigen::AngleAxisd(limits().use_mag ? delta_ : 0.0, Vec3::UnitZ()));
    q_ = (heading * q_acc_ * q_gyr_).normalized();
    state_.gyro_bias = bias_;
    state_.bias_sigma = std::sqrt(std::max(0.0, covariance_.diagonal().maxCoeff()));
    state_.at_rest = rest_;
    state_.mag_disturbed = disturbed_;
  }

  VqfParameters p_;
  Quat q_gyr_ = Quat::Identity(), q_acc_ = Quat::Identity();
  double delta_ = 0.0;
  Vec3 bias_ = Vec3::Zero();
  Eigen::Matrix3d covariance_;
  double p0_ = 0.0, process_noise_ = 0.0, motion_w_ = 0.0, vertical_w_ = 0.0, rest_w_ = 0.0;
  double coefficient_dt_ = 0.0, k_mag_ = 0.0, k_mag_ref_ = 0.0, k_mag_init_ = 1.0;
  ButterworthLowpass<3> acc_lp_, rest_gyr_lp_, rest_acc_lp_;
  ButterworthLowpass<9> motion_r_lp_;
  ButterworthLowpass<2> motion_bias_lp_, mag_norm_dip_lp_;
  double rest_time_ = 0.0;
  bool rest_ = false;
  double ref_norm_ = 0.0, ref_dip_ = 0.0, undisturbed_time_ = 0.0, reject_time_ = 0.0;
  double candidate_norm_ = -1.0, candidate_dip_ = 0.0, candidate_time_ = 0.0;
  bool disturbed_ = false;
};

struct VqfField {
  std::string_view key;
  double VqfParameters::*value;
  bool positive;  // must be > 0 (else >= 0)
};

constexpr VqfField kVqfFields[] = {
    {"tau_acc", &VqfParameters::tau_acc, true},
    {"tau_mag", &VqfParameters::tau_mag, true},
    {"bias_sigma_init", &VqfParameters::bias_sigma_init, true},
    {"bias_forgetting_time", &VqfParameters::bias_forgetting_time, true},
    {"bias_clip", &VqfParameters::bias_clip, false},
    {"bias_sigma_motion", &VqfParameters::bias_sigma_motion, true},
    {"bias_vertical_forgetting", &VqfParameters::bias_vertical_forgetting, false},
    {"bias_sigma_rest", &VqfParameters::bias_sigma_rest, true},
    {"rest_min_time", &VqfParameters::rest_min_time, false},
    {"rest_filter_tau", &VqfParameters::rest_filter_tau, true},
    {"rest_th_gyr", &VqfParameters::rest_th_gyr, false},
    {"rest_th_acc", &VqfParameters::rest_th_acc, false},
    {"mag_current_tau", &VqfParameters::mag_current_tau, true},
    {"mag_ref_tau", &VqfParameters::mag_ref_tau, true},
    {"mag_norm_th", &VqfParameters::mag_norm_th, false},
    {"mag_dip_th", &VqfParameters::mag_dip_th, false},
    {"mag_new_time", &VqfParameters::mag_new_time, false},
    {"mag_new_first_time", &VqfParameters::mag_new_first_time, false},
    {"mag_new_min_gyr", &VqfParameters::mag_new_min_gyr, false},
    {"mag_min_undisturbed_time", &VqfParameters::mag_min_undisturbed_time, false},
    {"mag_max_rejection_time", &VqfParameters::mag_max_rejection_time, false},
    {"mag_rejection_factor", &VqfParameters::mag_rejection_factor, true},
};

constexpr auto kVqfOptions = with_common_estimator_options(std::array<OptionSpec, 25>{{
    {"tau_acc", OptionType::Float, "3", "s: accelerometer low-pass time constant (inclination)"},
    {"tau_mag", OptionType::Float, "9", "s: magnetometer time constant (heading)"},
    {"motion_bias", OptionType::Boolean, "true", "estimate the gyroscope bias in motion"},
    {"rest_bias", OptionType::Boolean, "true", "estimate the gyroscope bias at rest"},
    {"mag_rejection", OptionType::Boolean, "true", "detect and reject magnetic disturbances"},
    {"bias_sigma_init", OptionType::Float, "0.5", "deg/s: initial bias uncertainty"},
    {"bias_forgetting_time", OptionType::Float, "100", "s: time for the bias uncertainty to grow from 0 to 0.1 deg/s"},
    {"bias_clip", OptionType::Float, "2", "deg/s: largest bias estimate"},
    {"bias_sigma_motion", OptionType::Float, "0.1", "deg/s: converged bias uncertainty in motion"},
    {"bias_vertical_forgetting", OptionType::Float, "0.0001",
     "factor: how much weaker the vertical bias is learned in motion"},
    {"bias_sigma_rest", OptionType::Float, "0.03", "deg/s: converged bias uncertainty at rest"},
    {"rest_min_time", OptionType::Float, "1.5", "s: quiet this long before rest is detected"},
    {"rest_filter_tau", OptionType::Float, "0.5", "s: rest detection low-pass time constant"},
    {"rest_th_gyr", OptionType::Float, "2", "deg/s: rest threshold for the gyroscope"},
    {"rest_th_acc", OptionType::Float, "0.5", "m/s^2: rest threshold for the accelerometer"},
    {"mag_current_tau", OptionType::Float, "0.05", "s: low-pass of the field's norm and dip"},
    {"mag_ref_tau", OptionType::Float, "20", "s: adaptation of the reference norm and dip"},
    {"mag_norm_th", OptionType::Float, "0.1", "relative: norm deviation that is a disturbance"},
    {"mag_dip_th", OptionType::Float, "10", "deg: dip deviation that is a disturbance"},
    {"mag_new_time", OptionType::Float, "20", "s: steady new field accepted after this long"},
    {"mag_new_first_time", OptionType::Float, "5", "s: the same for the very first reference"},
    {"mag_new_min_gyr", OptionType::Float, "20", "deg/s: motion needed to accept a new field"},
    {"mag_min_undisturbed_time", OptionType::Float, "0.5", "s: agreement needed to end a disturbance"},
    {"mag_max_rejection_time", OptionType::Float, "60", "s: longest full rejection of a disturbance"},
    {"mag_rejection_factor", OptionType::Float, "2", "gain divisor after the rejection time"},
}});

std::unique_ptr<OrientationEstimator> make_vqf_from_options(const OptionMap& options) {
  const OptionReader r(kVqfOptions, options);
  VqfParameters p;
  for (const VqfField& f : kVqfFields) {
    const double v = r.real(f.key);
    if (!(f.positive ? v > 0.0 : v >= 0.0))
      throw OptionError(std::string(f.key), f.positive ? "must be positive" : "must be zero or positive");
    p.*f.value = v;
  }
  p.motion_bias = r.boolean("motion_bias");
  p.rest_bias = r.boolean("rest_bias");
  p.mag_rejection = r.boolean("mag_rejection");
  return make_vqf_estimator(p, read_estimator_limits(r));
}

}  // namespace

std::unique_ptr<OrientationEstimator> make_vqf_estimator(const VqfParameters& parameters,
                                                         const EstimatorLimits& limits) {
  return std::make_unique<VqfEstimator>(parameters, limits);
}

const OrientationEstimatorEntry kVqfEstimator{
    "vqf", "VQF (Laidig & Seel 2023): bias estimation, rest detection, magnetic disturbance rejection",
    kVqfOptions, make_vqf_from_options};

}  // namespace posefair
