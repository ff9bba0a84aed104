#include "quality_scoring.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "posefair/core/causal_fairing.hpp"
#include "posefair/core/quality_metrics.hpp"

namespace posefair::tools {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The shift searched for view (b): from an output 50 ms early to 400 ms late (One Euro's
// default lags about 160 ms; one sample at 10 Hz is 100 ms). A 10 ms grid on a subsample of
// about 2000 samples finds the basin, a golden-section search on every sample the minimum
// within ±10 ms of it (to 0.06 ms). error(shift, stride) is the RMS error over every
// stride-th sample.
constexpr double kShiftLo = -0.05, kShiftHi = 0.40, kShiftStep = 0.01;

template <class Error>
double best_shift(const Error& error, std::size_t samples, double& best_error) {
  const std::size_t stride = std::max<std::size_t>(1, samples / 2000);
  double b = kShiftLo, eb = kInf;
  for (double s = kShiftLo; s <= kShiftHi + 1e-12; s += kShiftStep) {
    const double e = error(s, stride);
    if (e < eb) eb = e, b = s;
  }
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = b - kShiftStep, hi = b + kShiftStep;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double e1 = error(x1, 1), e2 = error(x2, 1);
  for (int it = 0; it < 12; ++it) {
    if (e1 < e2) {
      hi = x2, x2 = x1, e2 = e1;
      x1 = hi - g * (hi - lo);
      e1 = error(x1, 1);
    } else {
      lo = x1, x1 = x2, e1 = e2;
      x2 = lo + g * (hi - lo);
      e2 = error(x2, 1);
    }
  }
  const double s = e1 < e2 ? x1 : x2;
  best_error = std::min(e1, e2);
  return s;
}

// Linear interpolation of the gyroscope (sampled at the input times) at time t.
bool gyro_at(const QualitySequence& q, double t, Vec3& out, std::size_t& j) {
  const auto& ts = q.input.time;
  if (ts.size() < 2 || t < ts.front() || t > ts.back()) return false;
  if (j >= ts.size() || ts[j] > t) j = static_cast<std::size_t>(std::upper_bound(ts.begin(), ts.end(), t) - ts.begin()) - 1;
  while (j + 2 < ts.size() && ts[j + 1] <= t) ++j;
  if (j + 1 >= ts.size()) j = ts.size() - 2;
  const double f = (t - ts[j]) / (ts[j + 1] - ts[j]);
  out = (1.0 - f) * q.gyro[j] + f * q.gyro[j + 1];
  return true;
}

// BROAD's prediction truth at t: the optical sample nearest t (within half a period, in a
// scored movement phase) carried to t by the gyroscope (at most half a period of integration).
bool optical_truth_at(const QualitySequence& q, double t, Quat& out, std::size_t& j, std::size_t& gj) {
  const auto& ts = q.input.time;
  if (ts.empty() || t < ts.front() || t > ts.back()) return false;
  while (j + 1 < ts.size() && ts[j + 1] <= t) ++j;
  std::size_t k = j;
  if (j + 1 < ts.size() && ts[j + 1] - t < t - ts[j]) k = j + 1;
  const double d = t - ts[k];
  if (std::abs(d) > 0.5 / q.rate_hz + 1e-9 || !q.use[k]) return false;
  Vec3 w;
  if (!gyro_at(q, ts[k] + 0.5 * d + q.gyro_shift, w, gj)) return false;
  out = (q.input.orientation[k] * so3::from_rotation_vector(w * d)).normalized();
  return true;
}

}  // namespace

DeliveredStream delivered_as_sampled(const PoseSequence& input, std::vector<Quat> pose, double ns_per_sample) {
  DeliveredStream s;
  s.pose = std::move(pose);
  s.stamp = input.time;
  s.delivered = input.time;
  for (double& t : s.delivered) t += 1e-9 * ns_per_sample;
  s.ns_per_sample = ns_per_sample;
  return s;
}

DeliveredStream run_engine(const PoseSequence& input, const WindowConfig& config, std::span<const Vec3> gyro,
                           EngineState* final_state) {
  const auto t0 = std::chrono::steady_clock::now();
  FairingWindow window(config);
  std::vector<FairedPose> out(static_cast<std::size_t>(window.max_outputs_per_push()));
  DeliveredStream s;
  s.pose = input.orientation;
  s.stamp = input.time;
  s.delivered = input.time;
  const auto take = [&](int count, double now) {
    for (int k = 0; k < count; ++k) {
      const FairedPose& f = out[static_cast<std::size_t>(k)];
      const auto i = static_cast<std::size_t>(f.sequence);
      s.pose[i] = so3::aligned_to(f.orientation, input.orientation[i]);
      s.stamp[i] = f.time;
      s.delivered[i] = now;
    }
  };
  for (std::size_t i = 0; i < input.size(); ++i) {
    Sample sample;
    sample.sequence = i;
    sample.time = input.time[i];
    sample.orientation = input.orientation[i];
    if (!gyro.empty()) {
      sample.gyro = gyro[i];
      sample.flags |= kHasGyro;
    }
    take(window.push(sample, out), input.time[i]);
  }
  if (final_state != nullptr) *final_state = window.state();
  if (!input.time.empty()) take(window.flush(out), input.time.back());
  s.ns_per_sample = 1e9 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                    static_cast<double>(std::max<std::size_t>(1, input.size()));
  for (double& t : s.delivered) t += 1e-9 * s.ns_per_sample;
  return s;
}

double difference_to_fair_causal(const PoseSequence& input, const WindowConfig& config, const DeliveredStream& s) {
  const CausalResult r = fair_causal(input, config);
  double worst = 0.0;
  for (std::size_t i = 0; i < input.size(); ++i)
    worst = std::max(worst, so3::rotation_angle(r.poses.orientation[i], s.pose[i]));
  return worst;
}

SmoothingScore score_smoothing(const QualitySequence& q, bool broad, const DeliveredStream& s) {
  SmoothingScore r;
  const std::size_t n = q.input.size();
  r.ns_per_sample = s.ns_per_sample;
  r.jitter = jitter(s.pose, 1.0 / q.rate_hz, q.use);
  double delay = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    r.max_deviation = std::max(r.max_deviation, so3::rotation_angle(s.pose[i], q.input.orientation[i]));
    delay += s.delivered[i] - s.stamp[i];
  }
  r.delivery_ms = n ? 1e3 * delay / static_cast<double>(n) : 0.0;
  if (broad) {
    // Rates of consecutive outputs, each belonging to the mid-point of its two delivery times.
    std::vector<Vec3> rate;
    std::vector<double> mid;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      if (!q.use[i] || !q.use[i + 1]) continue;
      const double dt = s.stamp[i + 1] - s.stamp[i];
      if (!(dt > 0.0)) continue;
      rate.push_back(2.0 * so3::log(s.pose[i].conjugate() * s.pose[i + 1]) / dt);
      mid.push_back(0.5 * (s.delivered[i] + s.delivered[i + 1]));
    }
    const auto error = [&](double shift, std::size_t stride) {
      double sum = 0.0;
      std::size_t count = 0, j = 0;
      for (std::size_t k = 0; k < rate.size(); k += stride) {
        Vec3 g;
        if (!gyro_at(q, mid[k] - shift + q.gyro_shift, g, j)) continue;
        sum += (rate[k] - g).squaredNorm();
        ++count;
      }
      return count ? std::sqrt(sum / static_cast<double>(count)) : kInf;
    };
    r.error_delivered = error(0.0, 1);
    r.lag_ms = 1e3 * best_shift(error, rate.size(), r.error_aligned);
    r.relative_error = std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  const auto error = [&](double shift, std::size_t stride) {
    double sum = 0.0;
    std::size_t count = 0, cursor = 0;
    for (std::size_t i = 0; i < n; i += stride) {
      Quat g;
      if (!q.use[i] || !q.truth.at(s.delivered[i] - shift, g, cursor)) continue;
      const double e = so3::rotation_angle(s.pose[i], g);
      sum += e * e;
      ++count;
    }
    return count ? std::sqrt(sum / static_cast<double>(count)) : kInf;
  };
  r.error_delivered = error(0.0, 1);
  r.lag_ms = 1e3 * best_shift(error, n, r.error_aligned);
  // Relative (sample-to-sample) error: the output's rotation between consecutive deliveries
  // against the truth's over the same times.
  double sum = 0.0;
  std::size_t count = 0, cursor = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    Quat g0, g1;
    if (!q.use[i] || !q.use[i + 1] || !q.truth.at(s.delivered[i], g0, cursor)) continue;
    std::size_t c1 = cursor;
    if (!q.truth.at(s.delivered[i + 1], g1, c1)) continue;
    const double e = so3::rotation_angle(s.pose[i].conjugate() * s.pose[i + 1], g0.conjugate() * g1);
    sum += e * e;
    ++count;
  }
  r.relative_error = count ? std::sqrt(sum / static_cast<double>(count)) : kInf;
  return r;
}

PredictionScore score_prediction(const QualitySequence& q, bool broad, const std::vector<Quat>& predicted, double horizon_s) {
  PredictionScore r;
  r.jitter = jitter(predicted, 1.0 / q.rate_hz, q.use);
  double sum = 0.0;
  std::size_t count = 0, cursor = 0, gyro_cursor = 0;
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    if (!q.use[i]) continue;
    const double t = q.input.time[i] + horizon_s;
    Quat g;
    const bool ok = broad ? optical_truth_at(q, t, g, cursor, gyro_cursor) : q.truth.at(t, g, cursor);
    if (!ok) continue;
    const double e = so3::rotation_angle(predicted[i], g);
    sum += e * e;
    ++count;
  }
  r.error = count ? std::sqrt(sum / static_cast<double>(count)) : kInf;
  return r;
}

double optical_noise_bound(const QualitySequence& q) {
  const auto rates = body_rates(q.input.orientation, q.input.time);
  return rate_error(rates, q.input.time, q.gyro, q.gyro_shift, q.use) / q.rate_hz / std::sqrt(2.0);
}

}  // namespace posefair::tools
