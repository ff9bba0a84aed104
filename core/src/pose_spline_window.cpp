#include "posefair/core/pose_spline_window.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace posefair::geometric_splines {
namespace {

constexpr std::size_t kOpenEnd = std::numeric_limits<std::size_t>::max();

std::size_t half_width(const KnotVelocityOptions& v) {
  return v.estimator == KnotVelocityEstimator::LocalQuadraticFit ? static_cast<std::size_t>(v.fit_half_width) : 1;
}

}  // namespace

PoseSplineWindow::PoseSplineWindow(std::size_t capacity, const PoseSplineOptions& options, bool with_position)
    : capacity_(capacity), options_(options), with_position_(with_position), phi_(options.order) {
  validate(options);
  const std::size_t needed = 2 * half_width(options.velocity) + 2;
  if (capacity < needed)
    throw std::invalid_argument("spline window capacity " + std::to_string(capacity) + " is below the " +
                                std::to_string(needed) + " knots its velocity estimator needs");
  knots_.reserve(capacity);
}

std::size_t PoseSplineWindow::lookahead() const { return half_width(options_.velocity); }

void PoseSplineWindow::clear() {
  knots_.clear();
  first_index_ = 0;
  ready_ = 0;
}

bool PoseSplineWindow::push(double time, const Quat& orientation, const Vec3& position) {
  if (!std::isfinite(time) || (!knots_.empty() && !(time > knots_.back().time))) return false;
  if (knots_.size() == capacity_) {
    knots_.erase(knots_.begin());  // shifts in place, no allocation
    ++first_index_;
    if (ready_ > 0) --ready_;
  }
  PoseKnot k;
  k.time = time;
  k.orientation = orientation.normalized();
  if (!knots_.empty()) k.orientation = so3::aligned_to(k.orientation, knots_.back().orientation);
  else if (k.orientation.w() < 0.0) k.orientation.coeffs() *= -1.0;
  k.position = with_position_ ? position : Vec3::Zero();
  knots_.push_back(k);
  finalise_ready_knots();
  return true;
}

void PoseSplineWindow::finalise_ready_knots() {
  const std::size_t newest = first_index_ + knots_.size() - 1;
  while (ready_ < knots_.size()) {
    const std::size_t index = first_index_ + ready_;
    const auto [first, last] = knot_velocity_neighbourhood(options_.velocity, index, kOpenEnd);
    if (last > newest) break;
    // The capacity check in the constructor keeps the neighbourhood inside the window.
    const std::size_t begin = first - first_index_;
    estimate_pose_knot_velocity(options_.velocity.estimator, std::span(knots_).subspan(begin, last - first + 1),
                                index - first, with_position_);
    ++ready_;
  }
}

std::optional<std::pair<double, double>> PoseSplineWindow::ready_range() const {
  if (ready_ < 2) return std::nullopt;
  return std::pair{knots_.front().time, knots_[ready_ - 1].time};
}

bool PoseSplineWindow::evaluate(double t, SplinePose& out) const {
  if (ready_ < 2 || !(t >= knots_.front().time && t <= knots_[ready_ - 1].time)) return false;
  // Linear search from the newest: live queries sit near the end of a small window.
  std::size_t i = ready_ - 2;
  while (i > 0 && knots_[i].time > t) --i;
  out = evaluate_pose_segment(phi_, options_.manifold, knots_[i], knots_[i + 1], t);
  if (!with_position_) out.position = Vec3::Zero();
  return true;
}

}  // namespace posefair::geometric_splines
