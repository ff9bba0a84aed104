#include "posefair/core/prediction_check.hpp"

#include <algorithm>
#include <cmath>

namespace posefair {

void PredictionCheck::configure(double evaluations_per_second, bool lightest_first) {
  alpha_ = evaluations_per_second > 0.0 ? 1.0 - std::exp(-1.0 / (kTime * evaluations_per_second)) : 1.0;
  lightest_first_ = lightest_first;
  if (!lightest_first_) s_.weighed = true;
}

void PredictionCheck::restart() {
  s_ = State{};
  s_.weighed = !lightest_first_;
}

void PredictionCheck::note(std::span<const double, kCandidates> squared_errors) {
  // An exact mean over the first comparisons, then exponentially over kTime.
  s_.count = std::min(s_.count + 1.0, 1.0 / alpha_);
  const double a = std::max(1.0 / s_.count, alpha_);
  // The variance of such a mean per unit variance: 1/count, then a/(2 − a).
  const double spread = a > alpha_ ? a : a / (2.0 - a);
  // The standard error of candidate j's mean difference.
  const auto standard_error = [&](std::size_t j) {
    return std::sqrt(std::max(0.0, s_.mean_square[j] - s_.mean[j] * s_.mean[j]) * spread);
  };
  int best = 0;
  double best_mean = 0.0;
  for (std::size_t j = 1; j < kCandidates; ++j) {
    const double d = squared_errors[j] - squared_errors[0];
    s_.mean[j] += a * (d - s_.mean[j]);
    s_.mean_square[j] += a * (d * d - s_.mean_square[j]);
    if (s_.count >= kMinSamples && s_.mean[j] < best_mean && s_.mean[j] < -kSignificance * standard_error(j)) {
      best = static_cast<int>(j);
      best_mean = s_.mean[j];
    }
  }
  if (!s_.weighed) {
    constexpr auto l = static_cast<std::size_t>(kCandidates - 1);
    if (s_.count >= kMinSamples) {
      s_.weighed = true;
      if (best == 0) s_.choice = kCandidates - 1;  // and stays while it predicts better (below)
    } else if (s_.count >= kFirstSpread && s_.mean[l] > kSignificance * standard_error(l)) {
      s_.weighed = true;
    }
  }
  // A candidate taken stays while it still predicts better on average: where two candidates
  // predict alike, either will do.
  if (best == 0 && s_.choice > 0 && s_.mean[static_cast<std::size_t>(s_.choice)] < 0.0) best = s_.choice;
  s_.choice = best;
}

}  // namespace posefair
