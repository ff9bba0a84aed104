#include "posefair/core/gap_bridge.hpp"

#include "posefair/core/sampled_clock.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace posefair {
namespace {

// A step this much longer than the regular interval is a gap (at least one sample missing).
constexpr double kGapFactor = 1.5;

bool usable(const Sample& s) {
  const double n = s.orientation.norm();
  return std::isfinite(s.time) && std::isfinite(n) && std::abs(n - 1.0) < 1e-2 &&
         (!s.has_position() || s.position.allFinite());
}

// Room for the knots around one gap (central and Bessel estimates look one knot each way).
constexpr std::size_t kWindowKnots = 6;

}  // namespace

GapBridge::GapBridge(const GapBridgeOptions& options)
    : options_(options), spline_(kWindowKnots, options.spline, true) {
  // The held sample waits for exactly one successor: the estimate must look one knot ahead.
  if (options.spline.velocity.estimator == geometric_splines::KnotVelocityEstimator::LocalQuadraticFit)
    throw std::invalid_argument("gap bridging needs the central or bessel velocity estimate");
  if (!(options.max_gap > 0.0) || !std::isfinite(options.max_gap)) throw std::invalid_argument("max_gap must be positive");
  if (options.max_bridged < 1) throw std::invalid_argument("max_bridged must be at least 1");
}

std::size_t GapBridge::push(const Sample& s, std::span<Sample> out) {
  if (!usable(s) || (have_last_ && !(s.time > last_time_))) {
    // Not for the spline (the window's gate rejects or drops it). While a sample is held,
    // hand it on first so the order stays; the gap is then not bridged.
    std::size_t n = hand_on_held(out);
    out[n++] = s;
    return n;
  }
  if (have_last_ && s.time - last_time_ < kClumpStampStep) {
    // Read in a clump with the sample before (stamped µs apart): no knot (the spline's
    // velocities would be per µs) and no interval (the pause after the clump would be a gap of
    // thousands). After a held sample it waits with it for the next read, whose first sample is
    // the knot the held one's velocity needs; when too many wait, they go on unbridged.
    last_time_ = s.time;
    if (holding_ && clump_count_ < clump_.size()) {
      clump_[clump_count_++] = s;
      return 0;
    }
    std::size_t n = 0;
    if (holding_) {
      ++counters_.clumped;
      n = hand_on_held(out);
    }
    out[n++] = s;
    return n;
  }
  if (holding_) return release(s, out);

  const double dt = have_last_ ? s.time - last_time_ : 0.0;
  Sample knot = s;
  if (!knot.has_position()) knot.position = Vec3::Zero();
  if (have_last_ && interval_ > 0.0 && dt > kGapFactor * interval_) {
    if (dt <= options_.max_gap) {
      if (options_.interpolation == PoseInterpolation::MatrixLerp) return lerp_across(s, out);
      spline_.push(knot.time, knot.orientation, knot.position);
      holding_ = true;
      held_ = s;
      last_time_ = s.time;
      return 0;
    }
    ++counters_.too_long;
    spline_.clear();  // a spline across a long dropout means nothing
  } else if (have_last_) {
    interval_ = dt;
  }
  spline_.push(knot.time, knot.orientation, knot.position);
  before_ = s;
  have_last_ = true;
  last_time_ = s.time;
  out[0] = s;
  return 1;
}

// The sample after the held one has arrived: the held knot's velocity is final, so the gap
// (before_.time, held_.time) can be filled.
std::size_t GapBridge::release(const Sample& current, std::span<Sample> out) {
  Sample knot = current;
  if (!knot.has_position()) knot.position = Vec3::Zero();
  spline_.push(knot.time, knot.orientation, knot.position);
  std::size_t n = 0;
  const double gap = held_.time - before_.time;
  const auto missing = static_cast<std::size_t>(std::max(1.0, std::round(gap / interval_)) - 1.0);
  const std::size_t m = std::min(missing, options_.max_bridged);
  const auto range = spline_.ready_range();
  if (m > 0 && range && range->first <= before_.time && range->second >= held_.time) {
    const bool position = before_.has_position() && held_.has_position();
    for (std::size_t j = 1; j <= m; ++j) {
      const double t = before_.time + gap * static_cast<double>(j) / static_cast<double>(m + 1);
      geometric_splines::SplinePose p;
      if (!spline_.evaluate(t, p)) continue;
      Sample b = held_;
      b.time = t;
      b.device_time = 0.0;
      b.receive_time = held_.receive_time;
      b.orientation = p.orientation;
      b.position = position ? p.position : Vec3::Zero();
      b.flags = kBridged | (position ? kHasPosition : 0u);
      out[n++] = b;
    }
    ++counters_.gaps;
    counters_.samples += n;
  }
  // The current sample may itself end a gap: treat it as new, after the held one (and the
  // samples of its read).
  const double dt = current.time - last_time_;
  n += hand_on_held(out.subspan(n));
  last_time_ = current.time;
  if (dt > kGapFactor * interval_) {
    if (dt <= options_.max_gap) {
      holding_ = true;
      held_ = current;
      return n;
    }
    ++counters_.too_long;
    spline_.clear();
    spline_.push(knot.time, knot.orientation, knot.position);
  } else {
    interval_ = dt;
  }
  before_ = current;
  out[n++] = current;
  return n;
}

// The sample after a gap has arrived, and the lerp needs nothing more: fill the gap from
// before_ to it at once.
std::size_t GapBridge::lerp_across(const Sample& after, std::span<Sample> out) {
  const double gap = after.time - before_.time;
  const auto missing = static_cast<std::size_t>(std::max(1.0, std::round(gap / interval_)) - 1.0);
  const std::size_t m = std::min(missing, options_.max_bridged);
  std::size_t n = 0;
  if (m > 0) {
    const bool position = before_.has_position() && after.has_position();
    lerp_.prepare(before_.orientation, position ? before_.position : Vec3::Zero(), after.orientation,
                  position ? after.position : Vec3::Zero());
    for (std::size_t j = 1; j <= m; ++j) {
      const double f = static_cast<double>(j) / static_cast<double>(m + 1);
      Sample b = after;
      b.time = before_.time + gap * f;
      b.device_time = 0.0;
      lerp_.at(f, b.orientation, b.position);
      if (!position) b.position = Vec3::Zero();
      b.flags = kBridged | (position ? kHasPosition : 0u);
      out[n++] = b;
    }
    ++counters_.gaps;
    counters_.samples += m;
    counters_.lerp_fallbacks = lerp_.fallbacks();
  }
  out[n++] = after;
  before_ = after;
  last_time_ = after.time;
  return n;
}

std::size_t GapBridge::flush(std::span<Sample> out) { return hand_on_held(out); }

// The held sample and the samples of its read that waited with it, in order; it is then the
// last knot before any later gap.
std::size_t GapBridge::hand_on_held(std::span<Sample> out) {
  if (!holding_) return 0;
  std::size_t n = 0;
  out[n++] = held_;
  for (std::size_t i = 0; i < clump_count_; ++i) out[n++] = clump_[i];
  clump_count_ = 0;
  holding_ = false;
  before_ = held_;
  return n;
}

}  // namespace posefair
