#pragma once
// A stream's sample rate, from its sample times. What a transport does to the times decides how:
//   - jitter (times scattered around the sampling instants): the median interval, which a late,
//     early or dropped sample does not move;
//   - clumps (several samples read together and stamped microseconds apart, as a serial
//     adapter's latency timer, a USB or a BLE packet holding several reports delivers them):
//     there the median is the spacing inside a clump, not the stream's, so the rate is the
//     count of intervals over the time they span, taken over at least kClumpedRateSpan, so
//     that the clumps average out.
// A stream is clumped when one interval in kRateIntervals or more is shorter than a quarter of
// the mean interval, or than kShortestSampleInterval (a clump can fill the first intervals
// alone). Jitter that large is not jitter any more, and the mean serves it as well.
#include <array>
#include <span>

namespace posefair {

// The intervals that measure a live stream's rate, and the span a clumped one needs.
inline constexpr int kRateIntervals = 8;
inline constexpr int kMaxRateIntervals = 32;
inline constexpr double kClumpedRateSpan = 1.0;  // seconds
// Steps shorter than this (10 kHz) are the stamps of one read, not sampling intervals.
inline constexpr double kShortestSampleInterval = 1e-4;  // seconds

// Whether positive intervals are clumped (above).
bool intervals_are_clumped(std::span<const double> intervals);

// The rate (Hz) of a whole recording, times ascending: the median positive interval's, or
// for a clumped recording the mean's over its intervals up to `gap` long (longer ones are
// pauses, not intervals). 0 when there is no positive interval.
double sample_rate(std::span<const double> time, double gap = 0.25);

// The rate of a live stream, from its intervals as they come. Allocates nothing.
class StreamRateEstimate {
 public:
  // From the first `intervals` intervals (at most kMaxRateIntervals).
  explicit StreamRateEstimate(int intervals = kRateIntervals);
  // One interval: a positive step between consecutive samples that is not a gap.
  void note(double dt);
  // The rate (Hz): 0 until known, then fixed. The median of the first `intervals`
  // intervals, or, when they are clumped, the mean once kClumpedRateSpan has passed.
  double rate() const { return rate_; }
  // The stream's interval: 1/rate once known; before, the median of the intervals so far (their
  // mean if clumped); 0 before the first, or while they are all shorter than
  // kShortestSampleInterval (one read's stamps say nothing of the interval).
  double typical_interval() const;

 private:
  std::array<double, kMaxRateIntervals> first_{};
  int intervals_;
  long count_ = 0;  // intervals noted
  double sum_ = 0.0;
  bool clumped_ = false;
  double rate_ = 0.0;
};

}  // namespace posefair
