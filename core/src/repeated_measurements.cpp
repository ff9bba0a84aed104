#include "posefair/core/repeated_measurements.hpp"

#include <algorithm>

namespace posefair {

namespace {
// A run may be this much longer than the block's shortest: one for a source rate that does not
// divide the stream's (4 or 5 repeats of a 60 Hz source read at 250 Hz), more for long runs,
// whose polling jitter moves a report by a sample now and then.
int run_spread(int shortest) { return 1 + shortest / 3; }
constexpr int kLongestRun = 1 << 30;
}  // namespace

bool RepeatedMeasurements::note(const Sample& s) {
  const bool repeat = have_ && (s.flags & (kHasGyro | kHasAccel | kHasMag | kNoOrientation)) == 0 &&
                      s.flags == flags_ && s.orientation.coeffs() == orientation_.coeffs() &&
                      (!s.has_position() || s.position == position_);
  if (repeat) {
    run_ = std::min(run_ + 1, kLongestRun);  // a source stalled for weeks cannot overflow it
    // A run far longer than the block's longest is no steady source (a tracker that stalled
    // and repeats its last report): it ends the repeating at once, not at the block's end.
    if (repeating_ && run_ > 2 * longest_ + 1) {
      repeating_ = false;
      blocks_ = 0;
    }
    return true;
  }
  if (have_) end_run();
  have_ = true;
  orientation_ = s.orientation;
  position_ = s.position;
  flags_ = s.flags;
  run_ = 1;
  return false;
}

void RepeatedMeasurements::end_run() {
  if (runs_ == 0) {
    shortest_ = longest_ = run_;
  } else {
    shortest_ = std::min(shortest_, run_);
    longest_ = std::max(longest_, run_);
  }
  samples_ += run_;
  squares_ += static_cast<long>(run_) * run_;
  singles_ += run_ == 1 ? 1 : 0;
  if (++runs_ < kRepeatBlockRuns) return;
  const double n = kRepeatBlockRuns;
  const double mean = static_cast<double>(samples_) / n;
  const double variance = static_cast<double>(squares_) / n - mean * mean;
  // Steady: every run within the spread of the shortest. Jittered (a source whose reports come a
  // few milliseconds early or late): hardly a run of one sample, and the runs' spread under a
  // third of their mean. Chance repeats have runs of one sample (one in 2 at a repeat 1 time in
  // 2, one in 5 at 4 in 5) and a spread about their mean (a geometric run length's).
  const bool steady = longest_ - shortest_ <= run_spread(shortest_);
  const bool jittered = singles_ <= 1 && 9.0 * variance <= mean * mean;
  const bool regular = mean >= kMinMeanRun && (steady || jittered);
  blocks_ = regular ? std::min(blocks_ + 1, kRepeatBlocks) : 0;
  repeating_ = blocks_ >= kRepeatBlocks;
  runs_ = 0;
  samples_ = squares_ = 0;
  singles_ = 0;
}

}  // namespace posefair
