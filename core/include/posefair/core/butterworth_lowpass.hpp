#pragma once
// A second-order Butterworth low-pass filter on N channels, with the start-up VQF uses
// (Laidig & Seel 2023, sec. 3.2): the cutoff of time constant tau is f_c = √2 / (2π tau); the
// coefficients come from the bilinear transform with prewarping; for its first tau seconds the
// filter outputs the running mean of its input and then starts in the steady state of that
// mean, so a filter does not begin with a transient from zero.
#include <cmath>

#include <Eigen/Core>

namespace posefair {

// 1 - exp(-dt/tau): the gain of a first-order low-pass filter with time constant tau.
inline double first_order_gain(double tau, double dt) {
  return tau <= 0.0 ? 1.0 : 1.0 - std::exp(-dt / tau);
}

template <int N>
class ButterworthLowpass {
 public:
  using Vector = Eigen::Array<double, N, 1>;

  ButterworthLowpass() = default;
  ButterworthLowpass(double tau, double dt) { set_coefficients(tau, dt); }

  // New coefficients (time constant or sample time changed); keeps the state.
  void set_coefficients(double tau, double dt) {
    tau_ = tau;
    dt_ = dt;
    const double fc = std::sqrt(2.0) / (2.0 * M_PI * tau);
    const double c = std::tan(M_PI * fc * dt);
    const double d = c * c + std::sqrt(2.0) * c + 1.0;
    b0_ = c * c / d;
    a1_ = 2.0 * (c * c - 1.0) / d;
    a2_ = (1.0 - std::sqrt(2.0) * c + c * c) / d;
  }

  // Forget everything: the next inputs start a new running mean.
  void reset() {
    count_ = 0.0;
    elapsed_ = 0.0;
    initialised_ = false;
  }

  const Vector& step(const Vector& x) {
    if (!initialised_) {
      if (count_ == 0.0) sum_.setZero();
      sum_ += x;
      count_ += 1.0;
      elapsed_ += dt_;
      y_ = sum_ / count_;
      if (elapsed_ >= tau_) {
        // The steady state of the direct form II transposed for a constant input y_.
        s0_ = y_ * (1.0 - b0_);
        s1_ = y_ * (b0_ - a2_);
        initialised_ = true;
      }
      return y_;
    }
    y_ = b0_ * x + s0_;
    s0_ = 2.0 * b0_ * x - a1_ * y_ + s1_;
    s1_ = b0_ * x - a2_ * y_;
    return y_;
  }

  const Vector& value() const { return y_; }
  // Past the running-mean start-up: the output is the filter's.
  bool ready() const { return initialised_; }

 private:
  double tau_ = 1.0, dt_ = 0.01;
  double b0_ = 0.0, a1_ = 0.0, a2_ = 0.0;  // b1 = 2 b0, b2 = b0
  Vector s0_ = Vector::Zero(), s1_ = Vector::Zero(), y_ = Vector::Zero(), sum_ = Vector::Zero();
  double count_ = 0.0, elapsed_ = 0.0;
  bool initialised_ = false;
};

}  // namespace posefair
