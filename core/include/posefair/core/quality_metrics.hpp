#pragma once
// How good a smoothed orientation stream is: error to a truth, jitter, lag, and the angular
// rate against an independent gyroscope. All angles are physical rotation angles (radians);
// all functions are pure (no I/O), so the quality benchmark and tests share them.
#include <span>
#include <vector>

#include "posefair/core/pose_sequence.hpp"

namespace posefair {

struct ErrorStats {
  double rms = 0.0;
  double max = 0.0;
  std::size_t count = 0;
};

// Rotation angle between out[i] and truth[i] over the samples where use[i] (all if empty).
ErrorStats rotation_error(std::span<const Quat> out, std::span<const Quat> truth, std::span<const char> use = {});

// RMS angular acceleration of a stream (rad/s²): 2‖W² q_i‖ / dt² with the mean interval dt,
// over consecutive triples that are all used (all if use is empty).
double jitter(std::span<const Quat> q, double dt, std::span<const char> use = {});

// The delay τ (seconds, ≥ 0 means the output is late) minimising the RMS rotation error between
// out(t) and truth(t − τ), searched over whole-sample shifts −3 … max_shift (both streams on the
// same uniform grid) and refined by a parabola through the best three.
double lag_to_truth(std::span<const Quat> out, std::span<const Quat> truth, double dt, int max_shift,
                    std::span<const char> use = {});

// Body angular rate from consecutive samples, ω_i = 2 log(q_i⁻¹ q_{i+1}) / (t_{i+1} − t_i),
// belonging to the midpoint time. n−1 values.
std::vector<Vec3> body_rates(std::span<const Quat> q, std::span<const double> t);

// RMS of ‖ω_i − g(t_mid,i + shift)‖ with the gyroscope g linearly interpolated in time, over the
// intervals whose both ends are used. `gyro` is sampled at `t`.
double rate_error(std::span<const Vec3> rates, std::span<const double> t, std::span<const Vec3> gyro,
                  double shift, std::span<const char> use);

// The shift (seconds) minimising rate_error, searched from lo to hi in steps of `step`, then
// refined by a parabola. Returns {shift, error}.
struct ShiftFit {
  double shift = 0.0;
  double error = 0.0;
};
ShiftFit best_rate_shift(std::span<const Vec3> rates, std::span<const double> t, std::span<const Vec3> gyro,
                         std::span<const char> use, double lo, double hi, double step);

// Rotations A, B with truth_i ≈ A · est_i · B in the least-squares (chordal) sense, by
// alternating quaternion averages: a tracker's world frame and body frame rarely match the
// reference's. With fit_body = false, B = identity.
struct FrameAlignment {
  Quat world = Quat::Identity();
  Quat body = Quat::Identity();
};
FrameAlignment align_frames(std::span<const Quat> est, std::span<const Quat> truth, bool fit_body);

// The orientation of a sequence at time t by slerp between its neighbours (clamped at the ends).
Quat orientation_at(const PoseSequence& s, double t);

}  // namespace posefair
