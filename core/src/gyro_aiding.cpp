#include "posefair/core/gyro_aiding.hpp"

#include <algorithm>
#include <cmath>

namespace posefair {

GyroAiding::GyroAiding(const GyroAidingSettings& settings)
    : settings_(settings), offset_(std::clamp(settings.time_offset_s, -settings.max_time_offset_s, settings.max_time_offset_s)) {}

Vec3 GyroAiding::rate_at(std::span<const Sample> s, double t) const {
  const std::size_t n = s.size();
  // The samples around t: the last at or before it (the first, before the window), the next.
  std::size_t i = 0;
  if (t >= s[n - 1].time) {
    i = n - 1;
  } else if (t > s[0].time) {
    // Binary search: a window is at most a few hundred samples.
    i = static_cast<std::size_t>(std::upper_bound(s.begin(), s.end(), t, [](double v, const Sample& x) { return v < x.time; }) -
                                 s.begin()) - 1;
  }
  const bool inside = t > s[0].time && t < s[n - 1].time;
  // The readings around them: a missing one is bridged by its neighbours (at most
  // kMaxBridgedGyroReadings in a row, so these walks are short).
  std::size_t lo = i, hi = inside ? i + 1 : i;
  while (lo > 0 && !has_gyro_reading(s[lo])) --lo;
  while (hi + 1 < n && !has_gyro_reading(s[hi])) ++hi;
  const bool have_lo = has_gyro_reading(s[lo]), have_hi = has_gyro_reading(s[hi]);
  Vec3 raw = Vec3::Zero();
  if (inside && have_lo && have_hi && lo < hi) {
    const double f = (t - s[lo].time) / (s[hi].time - s[lo].time);
    raw = (1.0 - f) * s[lo].gyro + f * s[hi].gyro;
  } else if (have_lo && (t >= s[lo].time || !have_hi)) {
    raw = s[lo].gyro;  // at or past the last reading: held
  } else if (have_hi) {
    raw = s[hi].gyro;  // before the first reading: held
  }
  return settings_.mounting * (raw - bias_);
}

Vec3 GyroAiding::interval_residual(std::span<const Sample> samples, const Vec3& zeta, std::size_t k,
                                   Vec3* sensitivity) const {
  const double t0 = samples[k].time, t1 = samples[k + 1].time;
  const Vec3 w0 = rate_at(samples, t0 + offset_);
  const Vec3 w1 = rate_at(samples, t1 + offset_);
  *sensitivity = 0.5 * (w1 - w0);
  return zeta - 0.25 * (t1 - t0) * (w0 + w1);  // trapezoid, half-angle
}

void GyroAiding::update(std::span<const Sample> samples, std::span<const Vec3> zeta, std::span<Vec3> residual) {
  const std::size_t n = samples.size();
  if (n < 2) return;
  // An interval is complete once its gyro support ends at or before the newest reading.
  std::size_t newest = n - 1;
  while (newest > 0 && !has_gyro_reading(samples[newest])) --newest;
  const double newest_reading = samples[newest].time;
  // Back from the newest interval: the incomplete ones, and those this reading completed.
  // Older intervals keep the residual they had when they were completed.
  std::size_t first_completed = n - 1;  // none
  std::size_t last_completed = n - 1;
  bool seen_complete = false;
  for (std::size_t k = n - 1; k-- > 0;) {
    const double t1 = samples[k + 1].time;
    const bool complete = t1 + offset_ <= newest_reading;
    if (complete && seen_complete && t1 <= observed_until_) break;
    Vec3 sensitivity;
    residual[k] = interval_residual(samples, zeta[k], k, &sensitivity);
    if (!complete) continue;
    if (!seen_complete) last_completed = k;
    seen_complete = true;
    if (t1 <= observed_until_) break;
    first_completed = k;
  }
  // The completed intervals to the estimates, oldest first (the bias's line runs forward in
  // time). Bridged ones too: both estimates sum the orientation's jitter over consecutive
  // intervals, where it telescopes; leaving an interval out would leave its jitter in for good
  // (far more than the interpolated rate's error).
  for (std::size_t k = first_completed; k <= last_completed && k + 1 < n; ++k) {
    Vec3 sensitivity;
    const Vec3 r = interval_residual(samples, zeta[k], k, &sensitivity);
    observe(r, sensitivity, samples[k + 1].time - samples[k].time);
    observed_until_ = samples[k + 1].time;
  }
}

void GyroAiding::observe(const Vec3& r, const Vec3& s, double dt) {
  ++intervals_;
  elapsed_ += dt;
  if (settings_.estimate_time_offset) observe_offset(r, s, dt);
  // The bias once the offset is known (or the motion has not told it for offset_time_s):
  // before, the offset's error (δ·Δω/2, following the motion) would pass into the bias's
  // line, and the bias's error back into the offset.
  if (settings_.estimate_time_offset && !offset_estimated_ && elapsed_ < settings_.offset_time_s) return;
  // Bias: u = r − R b̂ dt/2 = ζ − R ω_gyro dt/2 is −R b dt/2 plus jitter that telescopes in
  // its running sum θ, so b is −2Rᵀ times the slope of θ over time: a least-squares line with
  // exponential forgetting, kept relative to the newest time (shift the sums by dt, add θ at 0).
  theta_ += r - settings_.mounting * bias_ * (0.5 * dt);
  const double forget_b = std::exp(-dt / settings_.bias_time_s);
  s2_ = forget_b * (s2_ - 2.0 * dt * s1_ + dt * dt * s0_);
  s1_ = forget_b * (s1_ - dt * s0_);
  s0_ = forget_b * s0_ + 1.0;
  y1_ = forget_b * (y1_ - dt * y0_);
  y0_ = forget_b * y0_ + theta_;
  span_ += dt;
  const double det = s0_ * s2_ - s1_ * s1_;
  if (span_ >= kBiasMinimumSpan && det > 0.0) bias_ = -2.0 * (settings_.mounting.conjugate() * ((s0_ * y1_ - s1_ * y0_) / det));
}

void GyroAiding::observe_offset(const Vec3& r, const Vec3& s, double dt) {
  // Offset: r(δ) ≈ r(δ̂) − (δ − δ̂)·s is zero on average at the true δ, so δ is the
  // least-squares solution of (r(δ̂) + δ̂·s) = δ·s over the intervals seen.
  const double forget = std::exp(-dt / settings_.offset_time_s);
  a_ = forget * a_ + (r + offset_ * s).dot(s);
  b_ = forget * b_ + s.squaredNorm();
  // The fit's noise. The orientation's jitter n enters r_j as n_{j+1} − n_j, so it meets s as
  // Σ n_j (s_{j−1} − s_j): its variance is σ_n² Σ‖Δs‖², with σ_n² half the residual's mean
  // square per component (which also holds the gyro's noise and what is left of the motion).
  c_ = forget * c_ + (s - last_s_).squaredNorm();
  last_s_ = s;
  const double alpha = 1.0 - forget;
  residual_var_ = intervals_ == 1 ? r.squaredNorm() / 3.0 : (1.0 - alpha) * residual_var_ + alpha * r.squaredNorm() / 3.0;
  if (!(b_ > 0.0)) return;
  const double standard_error = std::sqrt(0.5 * residual_var_ * c_) / b_;
  if (standard_error > kOffsetResolution) return;
  offset_ = std::clamp(a_ / b_, -settings_.max_time_offset_s, settings_.max_time_offset_s);
  offset_estimated_ = true;
}

GyroAidingState GyroAiding::state(bool active) const {
  GyroAidingState s;
  s.active = active;
  s.bias = bias_;
  s.time_offset_s = offset_;
  s.offset_estimated = offset_estimated_;
  s.intervals = intervals_;
  return s;
}

}  // namespace posefair
