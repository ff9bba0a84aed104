#pragma once
// Gyro-aided fairing (issue 17, docs/engine.md "Gyro-aided fairing"): when a stream's samples
// carry a measured orientation and a gyroscope reading, the window's smoothness term is put on
// the difference between the orientation's angular velocity and the gyro's,
//       μ Σ_j ‖D^{m−1}(W¹x − g)_j‖²,   g_j = ∫_{t_j}^{t_{j+1}} R(ω(t + δ) − b) dt / 2
// (half-angle, like so3::log), instead of on the angular velocity itself. The gyro measures the
// motion whose jitter the engine removes; what is left to smooth is only the slowly varying
// disagreement between the two sensors, so heavy smoothing costs no lag. For m = 2 a constant
// residual rate (a gyro bias) lies in the smoother's null space and passes without error.
// In the linear solver this is the same banded system with the measured increments
// ζ_j = log(z_j⁻¹ z_{j+1}) replaced by the residual increments r_j = ζ_j − g_j, so the emission
// rows and the adaptation (which now measures the residual's noise and motion) are reused.
//
// Estimated online, from intervals whose gyro support is complete (t_{j+1} + δ ≤ newest time):
//   bias b (gyro frame, rad/s): u_j = ζ_j − R ω_gyro dt/2 is −R b·dt/2 on average, and the
//     orientation's jitter telescopes in its running sum θ; b is −2Rᵀ times the slope of a
//     least-squares line through θ over time, with forgetting time bias_time_s (a line over
//     T seconds at rate f has slope noise σ·√(12/(f T³)): far below the jitter).
//   time offset δ (the gyro reading stamped t + δ measured the motion at t): to first order
//     r_j(δ) = r_j(δ̂) − (δ − δ̂) s_j with s_j = ∂g_j/∂δ = (ω(t_{j+1}+δ̂) − ω(t_j+δ̂))/2 (the
//     angular acceleration's work over the interval); a recursive least-squares fit of δ
//     relinearised at every interval, with forgetting time offset_time_s, applied once its
//     standard error is below kOffsetResolution. The bias is estimated from then on, or after
//     offset_time_s without one (before, each estimate's error would pass into the other).
// A missing reading (a sample without kHasGyro, or with a non-finite one) inside a gyro-aided
// window is bridged, up to kMaxBridgedGyroReadings in a row (FairingWindow restarts the window
// after a longer outage): the rate is interpolated between the readings around it, so the
// sample keeps its orientation data term and its intervals keep a residual of the same kind as
// their neighbours'. Those intervals become complete only once the next reading is in; they
// feed the estimates like the others (both sum the orientation's jitter over consecutive
// intervals, where it telescopes: leaving one out would leave its jitter in for good, far more
// than the interpolation's error). Why not drop the interval's gyro term instead: docs/fusion.md,
// "A missing gyro reading".
// No allocation: everything works on the window's own arrays.
#include <cstdint>
#include <span>

#include "posefair/core/sample.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

struct GyroAidingSettings {
  bool enabled = true;                  // use the gyro of samples that carry one (kHasGyro)
  Quat mounting = Quat::Identity();     // rotation from the gyro's frame to the orientation's body frame
  double time_offset_s = 0.0;           // δ to start from
  bool estimate_time_offset = true;
  double max_time_offset_s = 0.05;      // |δ| is kept within this
  double bias_time_s = 10.0;            // forgetting time of the bias's least squares
  double offset_time_s = 20.0;          // forgetting time of the offset's least squares
};

// The most readings in a row a gyro-aided window bridges; one more restarts it.
inline constexpr int kMaxBridgedGyroReadings = 2;

// A gyro reading the window can use: present and finite (a NaN would poison the window).
inline bool has_gyro_reading(const Sample& s) { return s.has_gyro() && s.gyro.allFinite(); }

// The standard error (s) below which the estimated time offset is applied.
inline constexpr double kOffsetResolution = 0.001;
// Seconds of gyro-aided intervals before the bias estimate is applied.
inline constexpr double kBiasMinimumSpan = 1.0;

struct GyroAidingState {
  bool active = false;           // the window is gyro-aided now
  Vec3 bias = Vec3::Zero();      // estimated gyro bias, rad/s, gyro frame
  double time_offset_s = 0.0;    // δ in use
  bool offset_estimated = false; // δ comes from the data (else it is the configured one)
  std::uint64_t intervals = 0;   // intervals that fed the estimates
};

class GyroAiding {
 public:
  explicit GyroAiding(const GyroAidingSettings& settings);

  // After a sample was appended to a gyro-aided window: samples holds the window's n samples
  // (times increasing; some with a reading, none more than kMaxBridgedGyroReadings in a row
  // without), zeta their n−1 measured increments. Writes the residual increments of the
  // intervals whose gyro support reaches past the newest reading (they are held at the newest
  // reading until the next arrives) and of those completed by it, and feeds each completed
  // interval once to the estimates, oldest first.
  void update(std::span<const Sample> samples, std::span<const Vec3> zeta, std::span<Vec3> residual);

  const GyroAidingSettings& settings() const { return settings_; }
  GyroAidingState state(bool active) const;

 private:
  // The bias-corrected gyro rate in the body frame at time t, linear between the readings
  // around t (across samples without one) and held beyond the window's first and last reading.
  Vec3 rate_at(std::span<const Sample> samples, double t) const;
  // The residual of interval k (samples k, k+1) and the sensitivity s of its gyro support, with
  // the bias and offset in use now.
  Vec3 interval_residual(std::span<const Sample> samples, const Vec3& zeta, std::size_t k, Vec3* sensitivity) const;
  void observe(const Vec3& residual, const Vec3& sensitivity, double dt);
  void observe_offset(const Vec3& residual, const Vec3& sensitivity, double dt);

  GyroAidingSettings settings_;
  Vec3 bias_ = Vec3::Zero();
  double offset_ = 0.0;
  bool offset_estimated_ = false;
  double observed_until_ = -1e300;  // end time of the newest interval fed to the estimates
  // The bias's line through θ (running sum of the bias-free residual) against time, with
  // forgetting, in time relative to the newest interval: Σw, Σw·t, Σw·t², Σw·θ, Σw·t·θ.
  Vec3 theta_ = Vec3::Zero();
  double s0_ = 0.0, s1_ = 0.0, s2_ = 0.0, span_ = 0.0;
  Vec3 y0_ = Vec3::Zero(), y1_ = Vec3::Zero();
  double a_ = 0.0, b_ = 0.0;        // the offset's least squares: Σ⟨r + δ̂s, s⟩, Σ‖s‖²
  double c_ = 0.0;                  // Σ‖s_j − s_{j−1}‖², for the fit's noise
  Vec3 last_s_ = Vec3::Zero();
  double residual_var_ = 0.0;       // mean square of the residual per component
  std::uint64_t intervals_ = 0;
  double elapsed_ = 0.0;  // seconds of intervals observed
};

}  // namespace posefair
