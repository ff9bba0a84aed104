#include "posefair/core/repeated_measurements.hpp"

#include <algorithm>

namespace posefair {

bool RepeatedMeasurements::note(const Sample& s) {
  const bool repeat = have_ && (s.flags & (kHasGyro | kHasAccel | kHasMag | kNoOrientation)) == 0 &&
                      s.flags == flags_ && s.orientation.coeffs() == orientation_.coeffs() &&
                      (!s.has_position() || s.position == position_);
  if (repeat) {
    run_ = std::min(run_ + 1, kLongestRun);  // a source stalled for weeks cannot overflow it
    // A run far longer than the block's longest is no steady source (a tracker that stalled
    // and repeats its last report): it ends the repeating at once, not at the block's end.
    runs_.check_open_run(run_);
    return true;
  }
  if (have_) runs_.end_run(run_);
  have_ = true;
  orientation_ = s.orientation;
  position_ = s.position;
  flags_ = s.flags;
  run_ = 1;
  return false;
}

}  // namespace posefair
