#include "quality_tuning.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace posefair::tools {

std::optional<std::size_t> pick_on_training(std::span<const std::size_t> candidates, std::span<const std::size_t> train,
                                            const std::function<double(std::size_t, std::size_t)>& relative_error,
                                            const std::function<double(std::size_t, std::size_t)>& lag_ms, double max_lag_ms) {
  std::optional<std::size_t> best;
  double best_mean = std::numeric_limits<double>::infinity();
  for (std::size_t c : candidates) {
    double sum = 0.0, lag = 0.0;
    bool ok = !train.empty();
    for (std::size_t s : train) {
      const double e = relative_error(c, s);
      if (!std::isfinite(e)) {
        ok = false;
        break;
      }
      sum += e;
      lag += lag_ms(c, s);
    }
    if (ok && lag / static_cast<double>(train.size()) <= max_lag_ms && sum / static_cast<double>(train.size()) < best_mean) {
      best_mean = sum / static_cast<double>(train.size());
      best = c;
    }
  }
  return best;
}

void Spread::add(double x) {
  if (count == 0) {
    min = max = x;
  } else {
    min = std::min(min, x);
    max = std::max(max, x);
  }
  mean += x;
  ++count;
}

void Spread::finish() {
  if (count) mean /= static_cast<double>(count);
}

std::string format_spread(const Spread& s) {
  char b[96];
  if (s.count == 0) return "–";
  if (s.count == 1 || s.min == s.max)
    std::snprintf(b, sizeof b, "%.4g", s.mean);
  else
    std::snprintf(b, sizeof b, "%.4g (%.4g–%.4g)", s.mean, s.min, s.max);
  return b;
}

}  // namespace posefair::tools
