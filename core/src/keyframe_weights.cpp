#include "posefair/core/keyframe_weights.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace posefair {
namespace {

void check_times(std::span<const double> key_times) {
  if (key_times.empty()) throw std::invalid_argument("no keyframes");
  for (std::size_t i = 1; i < key_times.size(); ++i)
    if (!(key_times[i] > key_times[i - 1])) throw std::invalid_argument("keyframe times must increase strictly");
}

// Segment i with key_times[i] <= t <= key_times[i+1] and the fraction u of the way along it.
std::pair<int, double> segment_of(std::span<const double> key_times, double t) {
  const int n = static_cast<int>(key_times.size());
  const auto it = std::upper_bound(key_times.begin(), key_times.end(), t);
  int i = static_cast<int>(it - key_times.begin()) - 1;
  i = std::clamp(i, 0, n - 2);
  const double u = std::clamp((t - key_times[i]) / (key_times[i + 1] - key_times[i]), 0.0, 1.0);
  return {i, u};
}

FrameWeights from_dense(const std::vector<double>& w) {
  FrameWeights f;
  double best = -1e300;
  for (int k = 0; k < static_cast<int>(w.size()); ++k) {
    if (std::abs(w[k]) < 1e-12) continue;  // rounding residue of cancelled weights
    f.terms.push_back({k, w[k]});
    if (w[k] > best) {
      best = w[k];
      f.origin = k;
    }
  }
  return f;
}

}  // namespace

std::vector<double> bspline_knots(std::span<const double> key_times, int degree) {
  const int n = static_cast<int>(key_times.size());
  std::vector<double> u(static_cast<std::size_t>(n + degree + 1));
  for (int i = 0; i <= degree; ++i) {
    u[i] = key_times.front();
    u[n + i] = key_times.back();
  }
  // Interior knots (de Boor's averaging): u_{j+p} = mean(t_j .. t_{j+p-1}), j = 1 .. n-p-1.
  for (int j = 1; j <= n - degree - 1; ++j) {
    double s = 0.0;
    for (int i = j; i < j + degree; ++i) s += key_times[i];
    u[j + degree] = s / degree;
  }
  return u;
}

std::vector<double> bspline_basis(std::span<const double> knots, int n, int degree, double t) {
  const int p = degree;
  t = std::clamp(t, knots[p], knots[n]);
  // The span k with knots[k] <= t < knots[k+1]; at the right end the last non-empty span.
  int k = p;
  while (k < n - 1 && t >= knots[k + 1]) ++k;
  std::vector<double> nb(p + 1, 0.0), left(p + 1, 0.0), right(p + 1, 0.0);
  nb[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - knots[k + 1 - j];
    right[j] = knots[k + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double tmp = nb[r] / (right[r + 1] + left[j - r]);
      nb[r] = saved + right[r + 1] * tmp;
      saved = left[j - r] * tmp;
    }
    nb[j] = saved;
  }
  std::vector<double> out(n, 0.0);
  for (int r = 0; r <= p; ++r) out[k - p + r] = nb[r];
  return out;
}

std::vector<std::vector<double>> subdivision_weights(int n, int levels) {
  std::vector<std::vector<double>> p(n, std::vector<double>(n, 0.0));
  for (int i = 0; i < n; ++i) p[i][i] = 1.0;
  if (n < 2) return p;
  auto lin = [n](const std::vector<double>& a, double wa, const std::vector<double>& b, double wb) {
    std::vector<double> r(n);
    for (int k = 0; k < n; ++k) r[k] = wa * a[k] + wb * b[k];
    return r;
  };
  for (int level = 0; level < levels; ++level) {
    const int m = static_cast<int>(p.size());
    // ERRATA item 1: the dummies reflect the second point about the end point (in log space).
    const auto before = lin(p[0], 2.0, p[1], -1.0);
    const auto after = lin(p[m - 1], 2.0, p[m - 2], -1.0);
    auto at = [&](int i) -> const std::vector<double>& { return i < 0 ? before : i >= m ? after : p[i]; };
    std::vector<std::vector<double>> next;
    next.reserve(2 * m - 1);
    for (int i = 0; i < m; ++i) {
      next.push_back(p[i]);
      if (i == m - 1) break;
      std::vector<double> r(n);
      for (int k = 0; k < n; ++k)
        r[k] = 9.0 / 16.0 * (at(i)[k] + at(i + 1)[k]) - 1.0 / 16.0 * (at(i - 1)[k] + at(i + 2)[k]);
      next.push_back(std::move(r));
    }
    p = std::move(next);
  }
  return p;
}

int subdivision_levels(int n, int frames) {
  if (n < 2) return 0;
  int m = 0;
  while (m < 16 && static_cast<long long>(n - 1) * (1LL << m) + 1 <= frames) ++m;
  return m;
}

std::vector<FrameWeights> frame_weights(InterpolationMethod method, std::span<const double> key_times,
                                        std::span<const double> frame_times) {
  check_times(key_times);
  const int n = static_cast<int>(key_times.size());
  std::vector<FrameWeights> out;
  out.reserve(frame_times.size());
  if (n == 1) {
    for (std::size_t f = 0; f < frame_times.size(); ++f) out.push_back(FrameWeights{{{0, 1.0}}, 0});
    return out;
  }
  switch (method) {
    case InterpolationMethod::Linear:
      for (double t : frame_times) {
        const auto [i, u] = segment_of(key_times, t);
        FrameWeights f;
        if (u < 1.0) f.terms.push_back({i, 1.0 - u});
        if (u > 0.0) f.terms.push_back({i + 1, u});
        f.origin = i;  // eq. 7: always about the segment's first key
        out.push_back(std::move(f));
      }
      break;
    case InterpolationMethod::Approximating: {
      const int degree = std::min(3, n - 1);
      const auto knots = bspline_knots(key_times, degree);
      for (double t : frame_times) out.push_back(from_dense(bspline_basis(knots, n, degree, t)));
      break;
    }
    case InterpolationMethod::Subdivision: {
      const int levels = subdivision_levels(n, static_cast<int>(frame_times.size()));
      const auto rows = subdivision_weights(n, levels);
      const int per_segment = 1 << levels;
      const int last = static_cast<int>(rows.size()) - 1;
      for (double t : frame_times) {
        const auto [i, u] = segment_of(key_times, t);
        // Eqs. 15-16: (1-s) of row j and s of row j+1, merged per key.
        const double pos = (i + u) * per_segment;
        const int j = std::min(static_cast<int>(std::floor(pos)), last);
        const double s = j == last ? 0.0 : pos - j;
        std::vector<double> w(n, 0.0);
        for (int k = 0; k < n; ++k) w[k] = (1.0 - s) * rows[j][k] + (s > 0.0 ? s * rows[j + 1][k] : 0.0);
        out.push_back(from_dense(w));
      }
      break;
    }
  }
  return out;
}

}  // namespace posefair
