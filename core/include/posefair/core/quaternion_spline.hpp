#pragma once
// Ramamoorthi & Barr, "Fast Construction of Accurate Quaternion Splines" (docs/quaternion-splines.md):
// interpolate keyframe orientations with a C¹ piecewise cubic Hermite curve in R⁴ that minimises
// the covariant-acceleration objective of eq. 3 (unit norm held by a soft α term), then refine it
// by inserting "variable frames" where the Euler–Lagrange error (eq. 4) is largest.
//
// Steps (Fig. 2): 1 keyframes (+ optional end angular velocities), 2 initial velocities by
// central differences (one-sided at free ends), 3 minimise over the free velocities, 4 insert
// variable frames at the starts of the segments with the highest mean |EL| (never at a
// keyframe), 5 minimise again over velocities and variable-frame positions; 4–5 repeat.
//
// Quaternions are handled as vectors (w, x, y, z) in R⁴; q′ = ½ ω q converts a spatial angular
// velocity ω (rad/s, physical) to a quaternion velocity.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/hermite_curve4.hpp"
#include "posefair/core/quaternion_spline_objective.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

struct SplineKeyframes {
  std::vector<double> time;       // strictly increasing, seconds
  std::vector<Quat> orientation;  // non-zero (normalised and hemisphere-aligned on use)
  // Spatial angular velocities at the first and last keyframe (rad/s). When absent that end's
  // velocity is free: guessed by a one-sided difference and optimised with the interior ones.
  std::optional<Vec3> omega_start, omega_end;
};

// (w, x, y, z) <-> Quat.
inline Vec4 to_vec4(const Quat& q) { return Vec4(q.w(), q.x(), q.y(), q.z()); }
inline Quat to_quat(const Vec4& v) { return Quat(v(0), v(1), v(2), v(3)); }
// q′ = ½ ω q, ω a spatial angular velocity (pure quaternion on the left).
Vec4 quaternion_velocity(const Vec3& omega, const Quat& q);

enum class SplineOptimizer { Lbfgs, Slsqp };
std::string_view to_string(SplineOptimizer m);

struct OptimizerSettings {
  // L-BFGS is the default: it reached the same objective as SLSQP several times faster in
  // the measurements of docs/quaternion-splines.md.
  SplineOptimizer method = SplineOptimizer::Lbfgs;
  double relative_tolerance = 1e-12;  // NLopt ftol_rel on the objective
  int max_evaluations = 20000;
};

// A curve plus which of its nodes are keyframes (fixed position) and variable frames.
struct QuaternionSpline {
  HermiteCurve4 curve;
  std::vector<char> is_variable_frame;  // one per node
  bool start_velocity_fixed = false;    // an angular velocity was given at that end
  bool end_velocity_fixed = false;

  bool velocity_free(std::size_t node) const;
  bool position_free(std::size_t node) const { return is_variable_frame[node] != 0; }
  int variable_frames() const;
  // The number of scalars the optimiser moves.
  int free_parameters() const;
};

// Step 2. Throws std::invalid_argument for fewer than two keyframes, times that do not increase
// strictly, or non-finite / zero quaternions.
QuaternionSpline initial_spline(const SplineKeyframes& keys);

struct OptimizeReport {
  double objective = 0.0;
  int evaluations = 0;
  double seconds = 0.0;
  std::string status;  // NLopt's outcome
};

// Steps 3 / 5: minimises the objective over the free velocities and variable-frame positions
// in place. NLopt L-BFGS or SLSQP with the analytic gradient.
OptimizeReport optimize_spline(QuaternionSpline& spline, const SplineObjective& objective,
                               const OptimizerSettings& settings);

// Step 4's segments: each keyframe interval cut into `per_interval` equal segments.
struct RefinementSegment {
  double start = 0.0, end = 0.0;
  bool starts_at_keyframe = false;
};
std::vector<RefinementSegment> refinement_segments(std::span<const double> key_times, int per_interval);

// Eq. 4: DEV = (1/Δt) ∫ |EL| dt over each segment, by `points`-point Gauss–Legendre.
std::vector<double> segment_deviation(const HermiteCurve4& curve, double alpha,
                                      std::span<const RefinementSegment> segments, int points);

// Step 4: adds up to `count` variable frames at the starts of the segments with the largest
// deviation, skipping segments that start at a keyframe or at an existing node. Returns how
// many were added (fewer when no such segment is left).
int add_variable_frames(QuaternionSpline& spline, std::span<const RefinementSegment> segments,
                        std::span<const double> deviation, int count);

// Splits every piece at its midpoint; the new nodes are variable frames (the curve is unchanged
// until optimised again). Used to estimate the optimum with many variable frames.
void split_every_piece(QuaternionSpline& spline);

// max over the curve of | |q(t)| − 1 |, sampled at `samples_per_piece` + 1 points per piece.
double max_norm_deviation(const HermiteCurve4& curve, int samples_per_piece = 64);

struct QuaternionSplineOptions {
  double alpha = 1000.0;            // soft unit-norm weight (the paper: ~1000 for unit key spacing)
  int variable_frames = 4;          // at most this many variable frames in total
  int frames_per_round = 1;         // frames added per refinement round (the paper's Fig. 3: 1)
  // Stop refining once a round lowers the objective by less than this fraction (0: never;
  // then exactly `variable_frames` are added if there is room).
  double target_improvement = 0.0;
  int segments_per_interval = 5;    // the paper: 4 to 5
  int quadrature_points = 8;        // Gauss–Legendre points per curve piece for OBJ
  int deviation_points = 4;         // Gauss–Legendre points per segment for DEV
  bool optimize = true;             // false: stop after step 2 (the unoptimised curve)
  OptimizerSettings optimizer;
};

// One circle of the paper's Fig. 3.
struct SplineStage {
  int variable_frames = 0;
  bool optimized = false;
  double objective = 0.0;
  double covariant = 0.0;           // ∫|q″ \ q|² alone
  double seconds = 0.0;             // algorithm time since the start (excludes these statistics)
  int evaluations = 0;              // objective evaluations in this stage
  double max_norm_deviation = 0.0;  // max | |q| − 1 |
  double max_el_deviation = 0.0;    // max over segments of DEV (eq. 4)
  double mean_el_deviation = 0.0;
};

struct QuaternionSplineResult {
  QuaternionSpline initial;  // after step 2
  QuaternionSpline spline;   // the final curve
  std::vector<RefinementSegment> segments;
  std::vector<SplineStage> stages;  // unoptimised, velocities only, then each refinement round
};

// The whole algorithm. Throws std::invalid_argument for bad keyframes or options.
QuaternionSplineResult build_quaternion_spline(const SplineKeyframes& keys, const QuaternionSplineOptions& options);

}  // namespace posefair
