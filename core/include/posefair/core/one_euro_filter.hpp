#pragma once
// One Euro filter (G. Casiez, N. Roussel, D. Vogel, "1€ Filter: A Simple Speed-Based Low-Pass
// Filter for Noisy Input in Interactive Systems", CHI 2012), as a reference filter for comparison.
// Header-only, no I/O, no allocation. One implementation of the algorithm, OneEuroFilter<T>, with a
// traits struct per value kind: double, fixed-size Eigen column vectors of double, unit quaternions.
//
// Algorithm, per sample x at time t (seconds):
//   first sample (after construction or reset()):  x̂ = x, dx̂ = 0, output x.
//   later samples:  dt  = t - t_prev                   (sampling rate re-derived from timestamps)
//                   dx  = (x ⊖ x̂_prev) / dt            (difference against the previous FILTERED value)
//                   dx̂  = lerp(alpha(dcutoff, dt); dx̂_prev, dx)
//                   fc  = mincutoff + beta·|dx̂|
//                   x̂   = lowpass(alpha(fc, dt); x̂_prev, x)
//   with alpha(fc, dt) = 1 / (1 + tau/dt), tau = 1/(2π·fc)   (smoothing_alpha_from_cutoff).
//
// Derivative reference: the authors' reference implementation (github.com/casiez/OneEuroFilter)
// differentiates against the previous filtered value (changed from the previous raw value in
// August 2023); its conformance file groundTruth.csv is produced that way, and differencing against
// the raw value misses it by ~0.08. This filter follows the reference.
//
// Timestamps: a sample whose timestamp is not later than the previous accepted one (dt <= 0,
// or NaN) is treated as a repeated / out-of-order sample: filter() returns the previous output and
// changes no state (the sample is dropped).
//
// Value kinds:
//   double                          lowpass = lerp, ⊖ = subtraction, |dx̂| = absolute value.
//   Eigen::Matrix<double, N, 1>     lowpass = component-wise lerp, |dx̂| = Euclidean norm, so with
//                                   beta != 0 the components share one cutoff (they are coupled).
//   Quat (unit quaternion)          x ⊖ x̂ = to_rotation_vector(x̂⁻¹·x): dx is the body-frame angular
//                                   velocity as a PHYSICAL rotation vector in rad/s (twice the
//                                   half-angle so3::log), |dx̂| in rad/s drives the cutoff; dx̂ is
//                                   low-passed as a 3-vector; lowpass = so3::slerp(alpha; x̂, x)
//                                   along the shorter arc. Inputs may have any non-zero norm and
//                                   either sign (q and -q give the same output rotation); the output
//                                   is unit, in the hemisphere of the previous output (the first
//                                   sample is passed through normalised, with its sign).
#include <cmath>
#include <stdexcept>

#include <Eigen/Core>

#include "posefair/core/exponential_slerp_filter.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

// Traits of a value kind for OneEuroFilter: Derivative type, and
//   identity()                  a default state value (never output before the first sample),
//   first(x)                    the value stored/output for the first sample,
//   zero_derivative()           dx̂ of the first sample,
//   difference(from, to)        to ⊖ from, in Derivative,
//   magnitude(d)                |d| >= 0,
//   lowpass(alpha, from, to)    value low-pass step from `from` towards `to` by alpha in (0, 1].
template <class T>
struct OneEuroTraits;  // undefined: only the kinds below are supported

template <>
struct OneEuroTraits<double> {
  using Derivative = double;
  static double identity() { return 0.0; }
  static double first(double x) { return x; }
  static double zero_derivative() { return 0.0; }
  static double difference(double from, double to) { return to - from; }
  static double magnitude(double d) { return std::abs(d); }
  static double lowpass(double alpha, double from, double to) { return alpha * to + (1.0 - alpha) * from; }
};

template <int N, int Options, int MaxRows>
struct OneEuroTraits<Eigen::Matrix<double, N, 1, Options, MaxRows, 1>> {
  static_assert(N != Eigen::Dynamic && N > 0, "OneEuroFilter: only fixed-size Eigen vectors (no allocation)");
  using Value = Eigen::Matrix<double, N, 1, Options, MaxRows, 1>;
  using Derivative = Value;
  static Value identity() { return Value::Zero(); }
  static Value first(const Value& x) { return x; }
  static Derivative zero_derivative() { return Derivative::Zero(); }
  static Derivative difference(const Value& from, const Value& to) { return to - from; }
  static double magnitude(const Derivative& d) { return d.norm(); }
  static Value lowpass(double alpha, const Value& from, const Value& to) {
    return alpha * to + (1.0 - alpha) * from;
  }
};

template <>
struct OneEuroTraits<Quat> {
  using Derivative = Vec3;  // physical rotation vector per second (rad/s), body frame
  static Quat identity() { return Quat::Identity(); }
  static Quat first(const Quat& q) { return q.normalized(); }
  static Derivative zero_derivative() { return Vec3::Zero(); }
  // `from` is always a previous output (unit), so its conjugate is its inverse; `to` may have any
  // non-zero norm and sign: so3::log ignores both.
  static Derivative difference(const Quat& from, const Quat& to) {
    return so3::to_rotation_vector(from.conjugate() * to);
  }
  static double magnitude(const Derivative& w) { return w.norm(); }
  // Shorter arc; renormalised so the norm does not drift over long streams.
  static Quat lowpass(double alpha, const Quat& from, const Quat& to) {
    return so3::slerp(alpha, from, to).normalized();
  }
};

template <class T, class Traits = OneEuroTraits<T>>
class OneEuroFilter {
 public:
  using Value = T;
  using Derivative = typename Traits::Derivative;

  // mincutoff > 0 (Hz), beta >= 0 (cutoff increase per unit of |derivative|, i.e. s/unit; for
  // quaternions per rad/s), dcutoff > 0 (Hz). Defaults are the reference implementation's.
  // Throws std::invalid_argument otherwise.
  explicit OneEuroFilter(double mincutoff = 1.0, double beta = 0.0, double dcutoff = 1.0)
      : mincutoff_(mincutoff), beta_(beta), dcutoff_(dcutoff) {
    if (!(mincutoff > 0.0) || !std::isfinite(mincutoff)) {
      throw std::invalid_argument("OneEuroFilter: mincutoff must be finite and > 0 Hz");
    }
    if (!(beta >= 0.0) || !std::isfinite(beta)) {
      throw std::invalid_argument("OneEuroFilter: beta must be finite and >= 0");
    }
    if (!(dcutoff > 0.0) || !std::isfinite(dcutoff)) {
      throw std::invalid_argument("OneEuroFilter: dcutoff must be finite and > 0 Hz");
    }
  }

  // Filters sample x taken at time t (seconds). See the header comment for the algorithm and the
  // rule for repeated or older timestamps (previous output returned, state unchanged).
  Value filter(const Value& x, double t) {
    if (!initialized_) {
      x_hat_ = Traits::first(x);
      dx_hat_ = Traits::zero_derivative();
      t_prev_ = t;
      initialized_ = true;
      return x_hat_;
    }
    const double dt = t - t_prev_;
    if (!(dt > 0.0)) return x_hat_;
    const Derivative dx = Traits::difference(x_hat_, x) / dt;
    const double a_d = smoothing_alpha_from_cutoff(dcutoff_, dt);
    dx_hat_ = a_d * dx + (1.0 - a_d) * dx_hat_;
    const double cutoff = mincutoff_ + beta_ * Traits::magnitude(dx_hat_);
    x_hat_ = Traits::lowpass(smoothing_alpha_from_cutoff(cutoff, dt), x_hat_, x);
    t_prev_ = t;
    return x_hat_;
  }

  // Forgets all samples; the next one is passed through.
  void reset() { initialized_ = false; }

  bool initialized() const { return initialized_; }
  // Last output and filtered derivative (per second); meaningful only when initialized().
  const Value& value() const { return x_hat_; }
  const Derivative& derivative() const { return dx_hat_; }

  double mincutoff() const { return mincutoff_; }
  double beta() const { return beta_; }
  double dcutoff() const { return dcutoff_; }

 private:
  double mincutoff_;
  double beta_;
  double dcutoff_;
  bool initialized_ = false;
  double t_prev_ = 0.0;
  Value x_hat_ = Traits::identity();
  Derivative dx_hat_ = Traits::zero_derivative();
};

using ScalarOneEuroFilter = OneEuroFilter<double>;
template <int N>
using VectorOneEuroFilter = OneEuroFilter<Eigen::Matrix<double, N, 1>>;
using QuatOneEuroFilter = OneEuroFilter<Quat>;

}  // namespace posefair
