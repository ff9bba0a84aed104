#include "posefair/core/repeated_measurements.hpp"

#include <algorithm>

namespace posefair {

namespace {
// A run may be this much longer than the block's shortest: one for a source rate that does not
// divide the stream's (4 or 5 repeats of a 60 Hz source read at 250 Hz), more for long runs,
// whose polling jitter moves a report by a sample now and then.
int run_spread(int shortest) { return 1 + shortest / 3; }
}  // namespace

bool RepeatedMeasurements::note(const Sample& s) {
  const bool repeat = have_ && (s.flags & (kHasGyro | kHasAccel | kHasMag | kNoOrientation)) == 0 &&
                      s.flags == flags_ && s.orientation.coeffs() == orientation_.coeffs() &&
                      (!s.has_position() || s.position == position_);
  if (repeat) {
    ++run_;
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
  if (++runs_ < kRepeatBlockRuns) return;
  const bool regular = longest_ - shortest_ <= run_spread(shortest_) &&
                       static_cast<double>(samples_) >= kMinMeanRun * kRepeatBlockRuns;
  blocks_ = regular ? std::min(blocks_ + 1, kRepeatBlocks) : 0;
  repeating_ = blocks_ >= kRepeatBlocks;
  runs_ = 0;
  samples_ = 0;
}

void RepeatedMeasurements::reset() { *this = RepeatedMeasurements{}; }

}  // namespace posefair
