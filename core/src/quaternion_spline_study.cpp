#include "posefair/core/quaternion_spline_study.hpp"

#include <cmath>

namespace posefair {

double mean_norm_deviation(const HermiteCurve4& curve, int samples) {
  double sum = 0.0;
  for (int k = 0; k < samples; ++k) {
    const double t = curve.start_time() + (curve.end_time() - curve.start_time()) * k / (samples - 1);
    sum += std::abs(curve.position(t).norm() - 1.0);
  }
  return sum / samples;
}

KeySetClaims key_set_claims(const SplineKeyframes& keys) {
  QuaternionSplineOptions o;  // α = 1000, 5 segments per interval, one frame per round
  KeySetClaims c;
  o.variable_frames = 4;
  const QuaternionSplineResult four = build_quaternion_spline(keys, o);
  o.variable_frames = 8;
  const QuaternionSplineResult eight = build_quaternion_spline(keys, o);
  o.variable_frames = 24;  // every segment start that is not a keyframe (6 intervals × 4)
  o.frames_per_round = 24;
  const QuaternionSplineResult all = build_quaternion_spline(keys, o);
  // As tests/core/quaternion_spline_reproduction_test.cpp and the docs estimate it.
  QuaternionSpline fine = all.spline;
  split_every_piece(fine);
  OptimizerSettings settings;
  settings.max_evaluations = 100000;
  c.optimum = optimize_spline(fine, SplineObjective(o.alpha, o.quadrature_points), settings).objective;
  c.objective_4 = four.stages.back().objective;
  c.objective_8 = eight.stages.back().objective;
  c.objective_24 = all.stages.back().objective;
  c.gap_4 = (c.objective_4 - c.optimum) / c.optimum;
  c.gap_8 = (c.objective_8 - c.optimum) / c.optimum;
  c.gap_24 = (c.objective_24 - c.optimum) / c.optimum;
  c.max_norm_deviation_4 = max_norm_deviation(four.spline.curve);
  c.mean_norm_deviation_4 = mean_norm_deviation(four.spline.curve);
  return c;
}

}  // namespace posefair
