#include "posefair/core/regular_runs.hpp"

#include <algorithm>

namespace posefair {

namespace {
// A run may be this much longer than the block's shortest: one for a source rate that does not
// divide the stream's (4 or 5 repeats of a 60 Hz source read at 250 Hz), more for long runs,
// whose polling jitter moves a report by a sample now and then.
int run_spread(int shortest) { return 1 + shortest / 3; }
}  // namespace

void RegularRuns::check_open_run(int length) {
  if (regular_ && length > 2 * longest_ + 1) {
    regular_ = false;
    blocks_ = 0;
  }
}

void RegularRuns::break_off() {
  regular_ = false;
  blocks_ = runs_ = 0;
  samples_ = squares_ = 0;
  singles_ = 0;
}

void RegularRuns::end_run(int length) {
  if (runs_ == 0) {
    shortest_ = longest_ = length;
  } else {
    shortest_ = std::min(shortest_, length);
    longest_ = std::max(longest_, length);
  }
  samples_ += length;
  squares_ += static_cast<long>(length) * length;
  singles_ += length == 1 ? 1 : 0;
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
  const bool regular = mean >= min_mean_run_ && (steady || jittered);
  blocks_ = regular ? std::min(blocks_ + 1, kRepeatBlocks) : 0;
  regular_ = blocks_ >= kRepeatBlocks;
  runs_ = 0;
  samples_ = squares_ = 0;
  singles_ = 0;
}

}  // namespace posefair
