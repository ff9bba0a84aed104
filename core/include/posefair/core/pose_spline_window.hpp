#pragma once
// Live resampling: a sliding window of the newest pose knots that evaluates the same spline as
// PoseSpline at any time inside its ready range. It allocates only in its constructor, so a
// real-time thread can push and evaluate.
//
// A knot's velocity estimate needs knots after it (1 for central/bessel, w for the fit, 2w at
// the very start of a stream), so the spline is final only up to the newest knot whose
// velocity is final: ready_range().second lags the newest sample by lookahead() samples (plus
// the segment itself when resampling at a rate: the added delay is lookahead()+1 input
// intervals at most). Away from the stream's end, values equal PoseSpline's on the same
// samples to rounding.
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "posefair/core/pose_spline.hpp"

namespace posefair::geometric_splines {

class PoseSplineWindow {
 public:
  // capacity >= 2 w + 2 knots (w = 1 for central/bessel, the half width for the fit);
  // throws std::invalid_argument for a smaller capacity or bad options.
  PoseSplineWindow(std::size_t capacity, const PoseSplineOptions& options, bool with_position);

  // Appends a sample (the oldest knot is dropped when full). Returns false and changes nothing
  // when time does not strictly increase on the newest knot or is not finite.
  bool push(double time, const Quat& orientation, const Vec3& position = Vec3::Zero());
  // Forgets every knot (e.g. after a gap too long to bridge).
  void clear();

  std::size_t size() const { return knots_.size(); }
  std::size_t capacity() const { return capacity_; }
  // Knots pushed after a knot before its velocity can be final, in steady state.
  std::size_t lookahead() const;
  // [first, last] where evaluate() answers; nullopt until two knots have final velocities.
  std::optional<std::pair<double, double>> ready_range() const;
  // The spline at t; false when t is outside ready_range().
  bool evaluate(double t, SplinePose& out) const;
  // The knots held (front = oldest); the first ready_count() have final velocities.
  const std::vector<PoseKnot>& knots() const { return knots_; }
  std::size_t ready_count() const { return ready_; }

 private:
  void finalise_ready_knots();

  std::size_t capacity_;
  PoseSplineOptions options_;
  bool with_position_;
  SmoothingFunction phi_;
  std::vector<PoseKnot> knots_;
  std::size_t first_index_ = 0;  // stream index of knots_[0]
  std::size_t ready_ = 0;
};

}  // namespace posefair::geometric_splines
