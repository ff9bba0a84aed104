#pragma once
// Geometric C^k splines through poses (orientation + optional position): the batch form for a
// whole sequence. Orientation on S^3 (eq. 22 on unit quaternions) or on SO(3) (eq. 16);
// position in R^3 (eq. 6) with the same k. Knot velocities are estimated from the data
// (knot_velocity.hpp). See docs/splines.md.
//
// Conventions: angular velocities are WORLD-frame, rad/s, physical angle (q_dot = 1/2 (0, w) q
// in the half-angle convention of so3.hpp). Knot orientations are made hemisphere-continuous
// (so3::make_continuous) before anything else; evaluated orientations lie in the hemisphere of
// their segment's first knot.
#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include "posefair/core/knot_velocity.hpp"
#include "posefair/core/pose_sequence.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/core/spline_smoothing_function.hpp"

namespace posefair::geometric_splines {

enum class OrientationManifold {
  Sphere,    // S^3: eq. 22 with the great arcs of eqs. 20-21 on the unit quaternions
  LieGroup,  // SO(3): eq. 16 with matrix exp/log
};
std::string_view to_string(OrientationManifold m);

struct PoseSplineOptions {
  int order = 2;  // k: the spline is C^k (1: the C^1 cubic-like curve; 2: C^2 with zero knot accelerations)
  OrientationManifold manifold = OrientationManifold::Sphere;
  KnotVelocityOptions velocity;
};
// Throws std::invalid_argument for an order outside 1..kMaxSplineOrder or a bad half width.
void validate(const PoseSplineOptions& options);

struct PoseKnot {
  double time = 0.0;
  Quat orientation = Quat::Identity();
  Vec3 angular_velocity = Vec3::Zero();  // world frame, rad/s
  Vec3 position = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();          // per second
};

struct SplinePose {
  Quat orientation = Quat::Identity();
  Vec3 position = Vec3::Zero();
};

// The spline between knots a and b (a.time < b.time) at time t (t may lie slightly outside
// [a.time, b.time]: the formulas continue smoothly).
SplinePose evaluate_pose_segment(const SmoothingFunction& phi, OrientationManifold manifold, const PoseKnot& a,
                                 const PoseKnot& b, double t);

// Velocity estimate for knots[self] from the contiguous neighbourhood `knots` (see
// knot_velocity_neighbourhood); writes its angular_velocity and (with_position) velocity.
void estimate_pose_knot_velocity(KnotVelocityEstimator estimator, std::span<PoseKnot> knots, std::size_t self,
                                 bool with_position);

class PoseSpline {
 public:
  // Knots = the samples, velocities estimated. Throws std::invalid_argument: fewer than 2
  // samples, a time that does not strictly increase ("sample i: ..."), bad options.
  PoseSpline(const PoseSequence& poses, const PoseSplineOptions& options);
  // Knots with their velocities already set (orientations are made continuous).
  PoseSpline(std::vector<PoseKnot> knots, bool with_position, const PoseSplineOptions& options);

  double start_time() const { return knots_.front().time; }
  double end_time() const { return knots_.back().time; }
  bool has_position() const { return with_position_; }
  const std::vector<PoseKnot>& knots() const { return knots_; }
  const PoseSplineOptions& options() const { return options_; }

  // At t in [start_time, end_time]; std::out_of_range outside.
  SplinePose evaluate(double t) const;
  // World-frame angular velocity (rad/s) and acceleration (rad/s^2) of the orientation spline at
  // t, by 4th-order central differences of the segment's own formula (not across knots).
  Vec3 angular_velocity(double t) const;
  Vec3 angular_acceleration(double t) const;

 private:
  std::vector<PoseKnot> knots_;
  std::vector<double> times_;
  bool with_position_;
  PoseSplineOptions options_;
  SmoothingFunction phi_;
};

// The spline of `poses` evaluated at `times` (each inside the data's time range, else
// std::out_of_range). The result has positions iff `poses` has them.
PoseSequence resample(const PoseSequence& poses, std::span<const double> times, const PoseSplineOptions& options);

}  // namespace posefair::geometric_splines
