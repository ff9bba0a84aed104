#include "posefair/core/quality_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace posefair {
namespace {

bool used(std::span<const char> use, std::size_t i) { return use.empty() || use[i] != 0; }

Quat average(std::span<const Quat> q) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const Quat& x : q) sum += (x.coeffs().dot(q[0].coeffs()) < 0 ? -x.coeffs() : x.coeffs());
  Quat r;
  r.coeffs() = sum.normalized();
  return r;
}

// Vertex of the parabola through (−1, a), (0, b), (1, c), clamped to [−1, 1].
double parabola_vertex(double a, double b, double c) {
  const double den = a - 2.0 * b + c;
  if (!(den > 0.0)) return 0.0;
  return std::clamp(0.5 * (a - c) / den, -1.0, 1.0);
}

}  // namespace

ErrorStats rotation_error(std::span<const Quat> out, std::span<const Quat> truth, std::span<const char> use) {
  ErrorStats s;
  double sum = 0.0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!used(use, i)) continue;
    const double e = so3::rotation_angle(out[i], truth[i]);
    sum += e * e;
    s.max = std::max(s.max, e);
    ++s.count;
  }
  s.rms = s.count ? std::sqrt(sum / static_cast<double>(s.count)) : 0.0;
  return s;
}

double jitter(std::span<const Quat> q, double dt, std::span<const char> use) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i + 2 < q.size(); ++i) {
    if (!used(use, i) || !used(use, i + 1) || !used(use, i + 2)) continue;
    const Vec3 w2 = so3::log(q[i + 1].conjugate() * q[i + 2]) - so3::log(q[i].conjugate() * q[i + 1]);
    const double a = 2.0 * w2.norm() / (dt * dt);
    sum += a * a;
    ++count;
  }
  return count ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
}

double lag_to_truth(std::span<const Quat> out, std::span<const Quat> truth, double dt, int max_shift,
                    std::span<const char> use) {
  // Shifts from −3 (an output that leads the truth) to max_shift.
  constexpr int kLead = 3;
  std::vector<double> err;
  for (int s = -kLead; s <= max_shift; ++s) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = static_cast<std::size_t>(std::max(0, s)); i < out.size(); ++i) {
      const auto jj = static_cast<std::ptrdiff_t>(i) - s;
      if (jj < 0 || jj >= static_cast<std::ptrdiff_t>(truth.size())) continue;
      const auto j = static_cast<std::size_t>(jj);
      if (!used(use, i) || !used(use, j)) continue;
      const double e = so3::rotation_angle(out[i], truth[j]);
      sum += e * e;
      ++count;
    }
    err.push_back(count ? sum / static_cast<double>(count) : std::numeric_limits<double>::infinity());
  }
  const auto best = static_cast<std::size_t>(std::min_element(err.begin(), err.end()) - err.begin());
  double frac = 0.0;
  if (best > 0 && best + 1 < err.size()) frac = parabola_vertex(err[best - 1], err[best], err[best + 1]);
  return (static_cast<double>(best) - kLead + frac) * dt;
}

std::vector<Vec3> body_rates(std::span<const Quat> q, std::span<const double> t) {
  std::vector<Vec3> w;
  for (std::size_t i = 0; i + 1 < q.size(); ++i) {
    const double dt = t[i + 1] - t[i];
    w.push_back(dt > 0 ? Vec3(2.0 * so3::log(q[i].conjugate() * q[i + 1]) / dt) : Vec3::Zero());
  }
  return w;
}

double rate_error(std::span<const Vec3> rates, std::span<const double> t, std::span<const Vec3> gyro, double shift,
                  std::span<const char> use) {
  double sum = 0.0;
  std::size_t count = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < rates.size(); ++i) {
    if (!used(use, i) || !used(use, i + 1)) continue;
    const double tm = 0.5 * (t[i] + t[i + 1]) + shift;
    while (j + 1 < t.size() && t[j + 1] < tm) ++j;
    if (j + 1 >= t.size() || t[j] > tm) continue;
    const double f = (tm - t[j]) / (t[j + 1] - t[j]);
    const Vec3 g = (1.0 - f) * gyro[j] + f * gyro[j + 1];
    sum += (rates[i] - g).squaredNorm();
    ++count;
  }
  return count ? std::sqrt(sum / static_cast<double>(count)) : std::numeric_limits<double>::infinity();
}

ShiftFit best_rate_shift(std::span<const Vec3> rates, std::span<const double> t, std::span<const Vec3> gyro,
                         std::span<const char> use, double lo, double hi, double step) {
  std::vector<double> err;
  for (double s = lo; s <= hi + 1e-12; s += step) err.push_back(rate_error(rates, t, gyro, s, use));
  const auto best = static_cast<std::size_t>(std::min_element(err.begin(), err.end()) - err.begin());
  double frac = 0.0;
  if (best > 0 && best + 1 < err.size()) frac = parabola_vertex(err[best - 1], err[best], err[best + 1]);
  ShiftFit fit;
  fit.shift = lo + (static_cast<double>(best) + frac) * step;
  fit.error = rate_error(rates, t, gyro, fit.shift, use);
  return fit;
}

FrameAlignment align_frames(std::span<const Quat> est, std::span<const Quat> truth, bool fit_body) {
  FrameAlignment a;
  std::vector<Quat> tmp(est.size());
  // Block coordinate descent: each half-step is the exact optimum given the other rotation,
  // so the chordal cost never rises; it converges linearly, slowly when the motion is poor in
  // some axis, hence the generous cap with an early stop.
  for (int it = 0; it < (fit_body ? 5000 : 1); ++it) {
    const Quat world_before = a.world, body_before = a.body;
    for (std::size_t i = 0; i < est.size(); ++i) tmp[i] = truth[i] * (est[i] * a.body).conjugate();
    a.world = average(tmp);
    if (!fit_body) break;
    for (std::size_t i = 0; i < est.size(); ++i) tmp[i] = (a.world * est[i]).conjugate() * truth[i];
    a.body = average(tmp);
    if (so3::dist(world_before, a.world) < 1e-13 && so3::dist(body_before, a.body) < 1e-13) break;
  }
  return a;
}

Quat orientation_at(const PoseSequence& s, double t) {
  const auto& ts = s.time;
  if (t <= ts.front()) return s.orientation.front();
  if (t >= ts.back()) return s.orientation.back();
  const auto it = std::upper_bound(ts.begin(), ts.end(), t);
  const auto j = static_cast<std::size_t>(it - ts.begin());
  const double f = (t - ts[j - 1]) / (ts[j] - ts[j - 1]);
  return so3::slerp(f, s.orientation[j - 1], s.orientation[j]);
}

}  // namespace posefair
