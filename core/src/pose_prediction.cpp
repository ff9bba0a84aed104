#include "posefair/core/pose_prediction.hpp"

#include <cmath>
#include <stdexcept>

namespace posefair {

void DeadReckoningPredictor::push(const Quat& q, double t) {
  const Quat u = q.normalized();
  if (!initialized_) {
    q_ = u;
    t_ = t;
    velocity_ = Vec3::Zero();
    initialized_ = true;
    return;
  }
  const double dt = t - t_;
  if (!(dt > 0.0)) return;  // repeated or out of order: dropped
  velocity_ = so3::to_rotation_vector(q_.conjugate() * u) / dt;
  q_ = u;
  t_ = t;
}

Quat DeadReckoningPredictor::predict(double horizon_s) const {
  return (q_ * so3::from_rotation_vector(velocity_ * horizon_s)).normalized();
}

SlerpExtrapolationPredictor::SlerpExtrapolationPredictor(double nominal_period_s) : period_(nominal_period_s) {
  if (!(nominal_period_s > 0.0) || !std::isfinite(nominal_period_s))
    throw std::invalid_argument("SlerpExtrapolationPredictor: the nominal period must be finite and > 0 s");
}

void SlerpExtrapolationPredictor::push(const Quat& q, double t) {
  if (count_ > 0 && !(t > t_)) return;  // repeated or out of order: dropped
  previous_ = count_ > 0 ? newest_ : q.normalized();
  newest_ = q.normalized();
  t_ = t;
  if (count_ < 2) ++count_;
}

Quat SlerpExtrapolationPredictor::predict(double horizon_s) const {
  if (count_ < 2) return newest_;
  return so3::slerp(1.0 + horizon_s / period_, previous_, newest_).normalized();
}

Quat OneEuroDeadReckoningPredictor::predict(double horizon_s) const {
  if (!filter_.initialized()) return Quat::Identity();
  return (filter_.value() * so3::from_rotation_vector(filter_.derivative() * horizon_s)).normalized();
}

}  // namespace posefair
