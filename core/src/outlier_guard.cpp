#include "posefair/core/outlier_guard.hpp"

#include <algorithm>
#include <cmath>

namespace posefair {

namespace {
// The median's step in log distance, up when a distance lands above it, down otherwise: a level
// three times higher or lower is reached in about 45 samples. The median, not a higher
// percentile: outliers the guard misses, and the few samples after each whose line they bend,
// would push a 95th percentile up and with it the threshold (a still stream with 1% outliers
// 0.15 rad off under noise of 0.005 had two in three held with it, all but two in 28 with the
// median).
constexpr double kRate = 0.025;
// The median moves by these factors (an exponential per sample was among the engine's costs).
const double kRateUp = std::exp(kRate), kRateDown = std::exp(-kRate);
// A sample is ordinary within three times the median (Gaussian noise lands further about once
// in 10 000 samples). At twice the median (about its 97.5th percentile) one outlier in twenty came after
// a sample that was not ordinary and was taken; the rule's point, that a motion building up over
// a sample or two puts the sample before off the line already, holds at either (on BROAD's
// optical stream both hold only samples the next one releases: 315 at twice, 452 at three times).
constexpr double kOrdinary = 3.0;
}  // namespace

OutlierGuard::OutlierGuard(double threshold, double scale) : threshold_(threshold), scale_(scale) {}

OutlierGuard::Verdict OutlierGuard::check(double step, Vec3& increment) {
  if (threshold_ <= 0.0) return Verdict::Take;
  Verdict verdict = Verdict::Take;
  const int held_run = held_run_;
  const bool held_before = held_run > 0;
  held_run_ = 0;
  // A released sample is a step the line runs through for the next kOutlierFitPoints − 1
  // samples; its prediction overshoots the stream meanwhile, so a sample far from it is no sign of
  // an outlier (the end of a burst that held one value, which with a lag would go out held).
  const bool settled = settling_ == 0;
  if (settling_ > 0) --settling_;
  if (count_ >= 2 && step > 0.0) {
    // The points in the chart of the newest one (at time 0, coordinate 0), going back.
    double u = 0.0, su = 0.0, suu = 0.0;
    Vec3 theta = Vec3::Zero(), sy = Vec3::Zero(), suy = Vec3::Zero();
    int i = head_;
    for (int n = 0; n < count_; ++n) {
      i = (i + kOutlierFitPoints - 2) % (kOutlierFitPoints - 1);
      u -= step_[static_cast<std::size_t>(i)];
      theta -= increment_[static_cast<std::size_t>(i)];
      su += u;
      suu += u * u;
      sy += theta;
      suy += u * theta;
    }
    const double points = count_ + 1.0;
    const double det = points * suu - su * su;
    if (det > 0.0) {
      const Vec3 slope = (points * suy - su * sy) / det;
      const Vec3 at_zero = (sy - slope * su) / points;
      const Vec3 predicted = at_zero + slope * step;
      const double distance = (increment - predicted).norm() / scale_;
      const double median = median_;
      const bool warm = seen_ >= kOutlierWarmUp;
      const bool held_now = warm && distance > kOutlierFloor && distance > threshold_ * median &&
                            ((ordinary_before_ && settled) || (held_before && held_run < kMaxHeldRun));
      ordinary_before_ = warm && distance <= kOrdinary * median;
      // The median is tracked in log space, by factors, and compared as itself.
      if (increment.isZero(0.0)) {
        // The same measurement again (a tracker that repeats its last value while it sees
        // nothing): not a new one, and the line soon predicts it exactly, so learning from it would
        // bring the median down towards nothing and, once the stream moves again, hold its noise.
      } else if (warm) {
        median_ *= distance > median ? kRateUp : kRateDown;
      } else {
        // Counted only up to the warm-up: a daemon's stream outlives an int's count of samples.
        const double d = std::max(distance, 1e-300);
        median_ = seen_ == 0 ? d : std::max(median_, d);
        ++seen_;
      }
      // Where the held sample was real, this one goes on from it as the line goes on: the line's
      // step from the held measurement. Where it was an outlier, the line's step from the
      // prediction. (From the held measurement alone, a fast motion's next step, 0.13 rad at
      // 60 Hz in a quick turn, weighed against it, and its deceleration was held as a burst.)
      if (held_before && (increment - held_offset_ - predicted).norm() < (increment - predicted).norm()) {
        // A motion started: the held sample goes back to its measurement, in the ring too.
        const int previous = (head_ + kOutlierFitPoints - 2) % (kOutlierFitPoints - 1);
        increment_[static_cast<std::size_t>(previous)] += held_offset_;
        increment -= held_offset_;
        verdict = Verdict::Release;
        settling_ = kOutlierFitPoints - 1;
      } else if (held_now) {
        held_offset_ = increment - predicted;
        held_run_ = held_run + 1;
        increment = predicted;
        verdict = Verdict::Hold;
      }
    }
  }
  step_[static_cast<std::size_t>(head_)] = step;
  increment_[static_cast<std::size_t>(head_)] = increment;
  head_ = (head_ + 1) % (kOutlierFitPoints - 1);
  count_ = std::min(count_ + 1, kOutlierFitPoints - 1);
  return verdict;
}

}  // namespace posefair
