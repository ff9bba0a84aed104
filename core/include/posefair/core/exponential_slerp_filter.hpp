#pragma once
// Reference filters for comparison (header-only, no I/O, no allocation).
//
// ExponentialSlerpFilter: first-order exponential smoothing of a unit-quaternion stream,
//   q̂_k = slerp(alpha_k; q̂_{k-1}, q_k)     (so3::slerp: shorter arc, so q and -q are one input),
// with either a fixed alpha per sample or a time constant tau (seconds), from which
//   alpha(tau, dt) = 1 / (1 + tau/dt)
// is re-derived from the spacing of successive timestamps. For a fixed axis and constant alpha
// the physical angle of the output after n samples of a step is (1 - (1-alpha)^n) of the step.
//
// Also defines the smoothing-factor helpers shared with the One Euro filter
// (one_euro_filter.hpp).
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "posefair/core/so3.hpp"

namespace posefair {

// Smoothing factor of a first-order low-pass with time constant tau (s) sampled after dt (s):
// alpha = 1 / (1 + tau/dt), in (0, 1] for tau >= 0 and dt > 0 (tau = 0 gives 1: pass-through).
inline double smoothing_alpha_from_time_constant(double tau, double dt) { return 1.0 / (1.0 + tau / dt); }

// The same for a cutoff frequency (Hz): tau = 1 / (2π·cutoff)  (Casiez et al., CHI 2012).
inline double smoothing_alpha_from_cutoff(double cutoff_hz, double dt) {
  return smoothing_alpha_from_time_constant(1.0 / (2.0 * std::numbers::pi * cutoff_hz), dt);
}

class ExponentialSlerpFilter {
 public:
  // Fixed smoothing factor per sample, alpha in (0, 1] (1 = pass-through). Timestamps are then
  // used only for the repeated/older-timestamp rule of filter().
  static ExponentialSlerpFilter with_alpha(double alpha) {
    if (!(alpha > 0.0 && alpha <= 1.0)) {
      throw std::invalid_argument("ExponentialSlerpFilter: alpha must be in (0, 1]");
    }
    return ExponentialSlerpFilter(Mode::kFixedAlpha, alpha);
  }

  // Time constant tau >= 0 in seconds; alpha = 1/(1 + tau/dt) from the timestamps.
  static ExponentialSlerpFilter with_time_constant(double tau_seconds) {
    if (!(tau_seconds >= 0.0) || !std::isfinite(tau_seconds)) {
      throw std::invalid_argument("ExponentialSlerpFilter: time constant must be finite and >= 0 s");
    }
    return ExponentialSlerpFilter(Mode::kTimeConstant, tau_seconds);
  }

  // Filters sample q (any non-zero quaternion; its norm and sign do not matter) taken at time t (s).
  // The first sample (after construction or reset()) is passed through, normalised.
  // A timestamp that is not later than the previous accepted one (dt <= 0, or NaN) marks a
  // repeated or out-of-order sample: the previous output is returned and no state changes.
  // The output is always a unit quaternion in the hemisphere of the previous output.
  Quat filter(const Quat& q, double t) {
    if (!initialized_) {
      out_ = q.normalized();
      t_prev_ = t;
      initialized_ = true;
      return out_;
    }
    const double dt = t - t_prev_;
    if (!(dt > 0.0)) return out_;
    const double alpha = mode_ == Mode::kFixedAlpha ? param_ : smoothing_alpha_from_time_constant(param_, dt);
    out_ = so3::slerp(alpha, out_, q).normalized();
    t_prev_ = t;
    return out_;
  }

  // Forgets all samples; the next one is passed through.
  void reset() { initialized_ = false; }

  bool initialized() const { return initialized_; }
  // Last output; meaningful only when initialized().
  const Quat& value() const { return out_; }
  bool has_fixed_alpha() const { return mode_ == Mode::kFixedAlpha; }
  // alpha (fixed mode) or tau in seconds (time-constant mode).
  double parameter() const { return param_; }

 private:
  enum class Mode { kFixedAlpha, kTimeConstant };
  ExponentialSlerpFilter(Mode mode, double param) : mode_(mode), param_(param) {}

  Mode mode_;
  double param_;
  bool initialized_ = false;
  double t_prev_ = 0.0;
  Quat out_ = Quat::Identity();
};

}  // namespace posefair
