#include "posefair/core/stream_rate.hpp"

#include <algorithm>
#include <numeric>
#include <vector>

#include "posefair/core/upper_median.hpp"

namespace posefair {

bool intervals_are_clumped(std::span<const double> intervals) {
  if (intervals.empty()) return false;
  const double mean = std::accumulate(intervals.begin(), intervals.end(), 0.0) / static_cast<double>(intervals.size());
  const auto short_ones = std::count_if(intervals.begin(), intervals.end(), [&](double dt) { return dt < 0.25 * mean || dt < kShortestSampleInterval; });
  return static_cast<double>(short_ones) * kRateIntervals >= static_cast<double>(intervals.size());
}

double sample_rate(std::span<const double> time, double gap) {
  std::vector<double> dt, ordinary;
  for (std::size_t i = 1; i < time.size(); ++i) {
    const double step = time[i] - time[i - 1];
    if (!(step > 0.0)) continue;
    dt.push_back(step);
    if (step <= gap) ordinary.push_back(step);
  }
  if (dt.empty()) return 0.0;
  if (intervals_are_clumped(ordinary))
    return static_cast<double>(ordinary.size()) / std::accumulate(ordinary.begin(), ordinary.end(), 0.0);
  return 1.0 / upper_median(dt);
}

StreamRateEstimate::StreamRateEstimate(int intervals) : intervals_(std::clamp(intervals, 1, kMaxRateIntervals)) {}

void StreamRateEstimate::note(double dt) {
  if (rate_ > 0.0 || !(dt > 0.0)) return;
  if (count_ < intervals_) first_[static_cast<std::size_t>(count_)] = dt;
  ++count_;
  sum_ += dt;
  if (count_ == intervals_) {
    clumped_ = intervals_are_clumped(std::span(first_).first(static_cast<std::size_t>(intervals_)));
    if (!clumped_) rate_ = 1.0 / typical_interval();
  }
  if (clumped_ && sum_ >= kClumpedRateSpan) rate_ = static_cast<double>(count_) / sum_;
}

double StreamRateEstimate::typical_interval() const {
  if (rate_ > 0.0) return 1.0 / rate_;
  if (count_ == 0) return 0.0;
  const auto n = static_cast<std::size_t>(std::min<long>(count_, intervals_));
  if (clumped_ || intervals_are_clumped(std::span(first_).first(n))) {
    const double mean = sum_ / static_cast<double>(count_);
    return mean < kShortestSampleInterval ? 0.0 : mean;
  }
  std::array<double, kMaxRateIntervals> sorted = first_;
  return upper_median(std::span(sorted).first(n));
}

}  // namespace posefair
