#include "posefair/core/fixed_rate_resampler.hpp"

#include <cmath>
#include <stdexcept>

namespace posefair {
namespace {

// Knots the spline window keeps: the lookahead of the widest velocity estimate each way, and
// the segment being evaluated.
std::size_t window_capacity(const geometric_splines::PoseSplineOptions& o) {
  const int w = o.velocity.estimator == geometric_splines::KnotVelocityEstimator::LocalQuadraticFit
                    ? o.velocity.fit_half_width
                    : 1;
  return static_cast<std::size_t>(4 * (w > 0 ? w : 1) + 4);
}

}  // namespace

FixedRateResampler::FixedRateResampler(const FixedRateResamplerOptions& options)
    : options_(options), spline_(window_capacity(options.spline), options.spline, true), period_(1.0 / options.rate_hz) {
  if (!(options.rate_hz > 0.0) || !std::isfinite(options.rate_hz)) throw std::invalid_argument("rate_hz must be positive");
  if (!(options.max_step > 0.0) || !std::isfinite(options.max_step)) throw std::invalid_argument("max_step must be positive");
  // Between two pushes the final range grows by at most one step (<= max_step).
  max_outputs_ = static_cast<std::size_t>(std::ceil(options.max_step * options.rate_hz)) + 2;
}

std::uint32_t FixedRateResampler::flags_between(double t) const {
  // The newest recorded pose at or before t, and the one after it.
  const std::size_t n = slots_ < kFlagSlots ? slots_ : kFlagSlots;
  std::uint32_t after = 0;
  bool have_after = false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = (slots_ - 1 - i) % kFlagSlots;
    if (slot_time_[k] <= t) {
      const std::uint32_t before = slot_flags_[k];
      const std::uint32_t next = have_after ? after : before;
      std::uint32_t flags = (before | next) & kNotMeasured;
      if ((before & kHasPosition) && (next & kHasPosition)) flags |= kHasPosition;
      return flags;
    }
    after = slot_flags_[k];
    have_after = true;
  }
  return after & (kNotMeasured | kHasPosition);
}

std::size_t FixedRateResampler::push(const FairedPose& stamped, std::span<FairedPose> out) {
  if (have_stamp_ && !(stamped.time > last_stamp_)) return 0;
  have_stamp_ = true;
  last_stamp_ = stamped.time;
  // Knots and grid on the times the samples were taken: a clump's stamps, 1 µs apart, would
  // make the spline's velocities and the lerp's fractions meaningless.
  FairedPose pose = stamped;
  pose.time = clock_.next(stamped.time, stamped.step);
  // Until the stream's rate is known a clump's sampled steps are its stamped ones, 1 µs: such
  // a pose is no knot (the first of each clump is; the spline through those is smooth, late by
  // up to a read, until the rate is known).
  if (have_last_ && pose.time - last_time_ < kClumpStampStep) return 0;
  if (options_.interpolation == PoseInterpolation::MatrixLerp) return push_lerp(pose, out);
  const bool restart = have_last_ && pose.time - last_time_ > options_.max_step;
  if (restart) {
    spline_.clear();
    slots_ = 0;
    ++restarts_;
  }
  if (!have_last_ || restart) next_ = static_cast<std::int64_t>(std::ceil(pose.time * options_.rate_hz));
  const std::size_t k = slots_ % kFlagSlots;
  slot_time_[k] = pose.time;
  slot_flags_[k] = pose.flags;
  ++slots_;
  spline_.push(pose.time, pose.orientation, (pose.flags & kHasPosition) ? pose.position : Vec3::Zero());
  have_last_ = true;
  last_time_ = pose.time;
  last_ = pose;

  const auto range = spline_.ready_range();
  if (!range) return 0;
  std::size_t n = 0;
  while (n < out.size() && n < max_outputs_) {
    const double t = static_cast<double>(next_) * period_;
    if (t > range->second) break;
    ++next_;
    geometric_splines::SplinePose p;
    if (t < range->first || !spline_.evaluate(t, p)) continue;
    FairedPose& g = out[n++];
    g.stream_id = pose.stream_id;
    g.sequence = pose.sequence;
    g.time = t;
    g.flags = flags_between(t);
    g.orientation = p.orientation;
    g.position = (g.flags & kHasPosition) ? p.position : Vec3::Zero();
    g.measured = g.orientation;  // nothing was measured at a grid time
    g.measured_position = g.position;
    g.step = 0.0;  // nor sampled: the grid's own spacing is the step
  }
  return n;
}

// The grid times in [last_.time, pose.time], each lerped between the two faired poses.
std::size_t FixedRateResampler::push_lerp(const FairedPose& pose, std::span<FairedPose> out) {
  if (have_last_ && !(pose.time > last_time_)) return 0;
  const bool restart = have_last_ && pose.time - last_time_ > options_.max_step;
  if (restart) ++restarts_;
  if (!have_last_ || restart) {
    next_ = static_cast<std::int64_t>(std::ceil(pose.time * options_.rate_hz));
    have_last_ = true;
    last_time_ = pose.time;
    last_ = pose;
    return 0;
  }
  const FairedPose a = last_;
  last_ = pose;
  last_time_ = pose.time;
  // Grid times left behind (out was too short last time) are skipped, not extrapolated.
  while (static_cast<double>(next_) * period_ < a.time) ++next_;
  if (static_cast<double>(next_) * period_ > pose.time) return 0;  // no grid time here: no logarithm

  const bool position = (a.flags & kHasPosition) && (pose.flags & kHasPosition);
  lerp_.prepare(a.orientation, position ? a.position : Vec3::Zero(), pose.orientation,
                position ? pose.position : Vec3::Zero());
  const std::uint32_t flags = ((a.flags | pose.flags) & kNotMeasured) | (position ? kHasPosition : 0u);
  const double span = pose.time - a.time;
  std::size_t n = 0;
  while (n < out.size() && n < max_outputs_) {
    const double t = static_cast<double>(next_) * period_;
    if (t > pose.time) break;
    ++next_;
    FairedPose& g = out[n++];
    g.stream_id = pose.stream_id;
    g.sequence = pose.sequence;
    g.time = t;
    g.flags = flags;
    lerp_.at((t - a.time) / span, g.orientation, g.position);
    if (!position) g.position = Vec3::Zero();
    g.measured = g.orientation;  // nothing was measured at a grid time
    g.measured_position = g.position;
    g.step = 0.0;  // nor sampled: the grid's own spacing is the step
  }
  return n;
}

}  // namespace posefair
