#pragma once
// A stream read faster than its source updates: each measurement repeated until the next.
//
// A tracker that measures at 60 Hz but is polled at 250 Hz (a webcam head tracker feeding a
// 250 Hz filter, a USB device read faster than its reports change) delivers every measurement
// four or five times, exactly. Read at the stream's rate, such a stream has its noise spread
// over a quarter of the samples and its motion in steps: the engine takes the steps for motion
// and barely smooths it (docs/engine.md, "Streams resampled from a lower rate"). Its samples
// are evenly spaced at the source's rate once the repeats are set aside, so the engine fairs the
// measurements alone and carries each repeat forward from the poses before it.
//
// Exact repeats also come from a quantised sensor whose value did not change, at random: those
// are measurements. They are told apart by regularity (regular_runs.hpp): a source read at a
// steady rate repeats each measurement nearly the same number of times (⌊f/f_s⌋ or one more), and
// a stream is taken as repeating its source only where its runs (a measurement and its repeats)
// come regularly and average at least kMinMeanRun samples. Chance repeats seldom pass. The steady rule: with a
// repeat 1 time in 3, 64 runs all of 1 or 2 samples come once in 1900, and each block's 32 of
// them half 2s once in 500 more (about once in 10⁹ pairs of blocks). The jittered rule hardly
// ever: their runs of one sample are common (half of them at a repeat 1 time in 2, a fifth at 4
// in 5), and their runs spread about as widely as their mean (a geometric length's). A tracker
// that stalled repeats its last report: a run far longer than the block's longest.
// No allocation; O(1) per sample.
#include "posefair/core/regular_runs.hpp"
#include "posefair/core/sample.hpp"

namespace posefair {

inline constexpr double kMinMeanRun = 1.5;

class RepeatedMeasurements {
 public:
  // Notes a sample (before the gate) and says whether it repeats the measurement before it exactly
  // (orientation and position as given; never a sample with raw inertial readings, which are
  // measured anew each time).
  bool note(const Sample& s);
  // Whether the stream repeats its measurements (above): its rate is its source's.
  bool repeating() const { return runs_.regular(); }

 private:
  bool have_ = false;
  Quat orientation_ = Quat::Identity();
  Vec3 position_ = Vec3::Zero();
  std::uint32_t flags_ = 0;
  int run_ = 0;  // samples in the current run: the measurement and its repeats so far
  RegularRuns runs_{kMinMeanRun};
};

}  // namespace posefair
