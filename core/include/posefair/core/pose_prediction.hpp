#pragma once
// Reference orientation predictors (latency compensation as VR runtimes do it), the baselines
// of the quality benchmark's prediction table (docs/benchmarks.md). Each is fed the stream
// sample by sample with push(q, t) and asked for the pose at t_k + h with predict(h), where
// t_k is the newest sample's time; one push can serve several horizons. No I/O, no allocation.
//
// Timestamps follow the reference filters' rule: a sample whose time is not later than the
// previous accepted one (or NaN) is dropped and changes nothing. Until a second sample has
// arrived there is no velocity and predict(h) returns the newest sample.
#include "posefair/core/one_euro_filter.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

// Constant angular velocity from the last two samples, as VRPN's dead-reckoning tracker
// filter does for a tracker that reports no velocity: ω = to_rotation_vector(q_{k−1}⁻¹ q_k) /
// (t_k − t_{k−1}) (body frame, rad/s), and q(t_k + h) = q_k · exp(ω h) (physical angle |ω| h).
class DeadReckoningPredictor {
 public:
  void push(const Quat& q, double t);
  Quat predict(double horizon_s) const;
  // Body-frame angular velocity (rad/s) from the last two samples; zero before the second.
  const Vec3& velocity() const { return velocity_; }
  bool initialized() const { return initialized_; }
  void reset() { initialized_ = false; velocity_ = Vec3::Zero(); }

 private:
  bool initialized_ = false;
  double t_ = 0.0;
  Quat q_ = Quat::Identity();
  Vec3 velocity_ = Vec3::Zero();
};

// SlimeVR-style slerp extrapolation: the geodesic from the previous sample to the newest one,
// continued past 1 by h/Δ, q(t_k + h) = slerp(1 + h/Δ; q_{k−1}, q_k), with Δ the stream's
// nominal sample period given at construction (a frame-based predictor assumes steady frames).
// On evenly spaced samples this is the same rotation as DeadReckoningPredictor (slerp(1 + s; a,
// b) = b (a⁻¹b)^s); across a dropout it extrapolates the longer step by the nominal period.
class SlerpExtrapolationPredictor {
 public:
  // nominal_period_s > 0 and finite; throws std::invalid_argument otherwise.
  explicit SlerpExtrapolationPredictor(double nominal_period_s);
  void push(const Quat& q, double t);
  Quat predict(double horizon_s) const;
  void reset() { count_ = 0; }

 private:
  double period_;
  int count_ = 0;  // accepted samples, saturating at 2
  double t_ = 0.0;
  Quat previous_ = Quat::Identity();
  Quat newest_ = Quat::Identity();
};

// One Euro (one_euro_filter.hpp) followed by dead reckoning on the filter's own filtered
// derivative: q(t_k + h) = q̂_k · exp(dx̂_k h). The derivative is the one the filter uses for
// its cutoff (raw sample against the previous filtered value, low-passed at dcutoff), so with
// a constant angular velocity ω and β = 0 it settles at ω/α (α the position smoothing factor)
// while q̂ trails the input by (1 − α)/α samples of motion: the prediction then misses by
// ω (1 − α)/α (h − Δ) for sample period Δ. That is the baseline as users would build it.
class OneEuroDeadReckoningPredictor {
 public:
  OneEuroDeadReckoningPredictor(double mincutoff, double beta, double dcutoff) : filter_(mincutoff, beta, dcutoff) {}
  void push(const Quat& q, double t) { filter_.filter(q, t); }
  Quat predict(double horizon_s) const;
  const QuatOneEuroFilter& filter() const { return filter_; }
  void reset() { filter_.reset(); }

 private:
  QuatOneEuroFilter filter_;
};

}  // namespace posefair
