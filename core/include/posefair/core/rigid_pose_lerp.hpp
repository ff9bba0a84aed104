#pragma once
// Alexa's lerp of the 4x4 rigid transform [R p; 0 1] between two neighbouring samples, for the
// daemon's gap bridging and resampling with [stream.spline] pose_interpolation = "matrix-lerp"
// (docs/splines.md, "In the daemon"). e^{t log(B A^-1)} A is the screw motion from A to B: a
// body that turns and moves at constant rates about one axis (a screw) is reproduced exactly,
// where slerp and a straight line for the position cut the helix's chord.
//
// One interval is prepared once (one matrix logarithm), then each time in it costs one matrix
// exponential and a product. Nothing allocates on the way a rigid pose takes.
//
// A step of pi/2 or more in rotation is refused by lerp (Section 3.2 of Hawkins & Grimm). Such
// an interval is interpolated with slerp and a straight line for the position instead (the
// "separate" linear interpolation between the same two samples), and counted: it needs no
// other sample, so the delay stays the lerp's, and it is a rigid pose on the shorter arc.
#include <cstdint>
#include <optional>

#include "posefair/core/linear_combination.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

// How the live gap bridge and resampler interpolate poses ([stream.spline] pose_interpolation).
enum class PoseInterpolation {
  Spline,      // "spline": the C^k geometric spline, on rotation and position separately
  MatrixLerp,  // "matrix-lerp": Alexa's lerp of the 4x4 transform between the two neighbours (C^0)
};

// The logarithm's settings for a step between neighbouring samples: precise() with fewer square
// roots and a longer series (eps1 = 0.05, up to 20 terms). The square roots' residual is
// divided by eps1, so this reaches ~1e-13 where precise() leaves ~1e-10 and the paper's
// constants ~1e-4 (measured against slerp: tests/core/rigid_pose_lerp_tests.cpp). The series
// needs at most 14 terms below eps1 = 0.05 to reach eps2 = 1e-17, so the cap is never hit.
inline CombinationOptions rigid_step_options() {
  CombinationOptions o = CombinationOptions::precise();
  o.log.epsilon1 = 0.05;
  o.log.max_series_terms = 20;
  return o;
}

class RigidPoseLerp {
 public:
  explicit RigidPoseLerp(const CombinationOptions& options = rigid_step_options()) : options_(options) {}

  // Prepares the interval from pose a to pose b (positions zero for a stream without one:
  // the lerp of two rotations is slerp). Returns false when lerp refused the step and the
  // interval is interpolated separately (slerp + straight line).
  bool prepare(const Quat& qa, const Vec3& pa, const Quat& qb, const Vec3& pb);
  // The pose at fraction t of the interval (0: a, 1: b). The orientation lies in a's hemisphere.
  void at(double t, Quat& q, Vec3& p);
  bool matrix() const { return lerp_.has_value(); }
  // Intervals (and, should an exponential ever fail, single poses) interpolated separately.
  std::uint64_t fallbacks() const { return fallbacks_; }

 private:
  CombinationOptions options_;
  std::optional<PreparedLerp> lerp_;
  Quat qa_ = Quat::Identity(), qb_ = Quat::Identity();
  Vec3 pa_ = Vec3::Zero(), pb_ = Vec3::Zero();
  std::uint64_t fallbacks_ = 0;
};

}  // namespace posefair
