#pragma once
// Whether a stream's runs come regularly: the test that tells a stream resampled from a slower
// source (each measurement repeated, or slerped to the next) from chance.
//
// A run is a measurement and the samples up to the next one (repeated_measurements.hpp: a
// measurement and its repeats; slerped_measurements.hpp: the samples between two kinks). A source
// read at a steady rate puts nearly the same number of samples in each (⌊f/f_s⌋ or one more), so
// the runs are taken as regular only after kRepeatBlocks blocks of kRepeatBlockRuns runs in a row
// that average at least a minimum length and are either steady (every run within a spread of the
// shortest) or jittered (a source whose reports come a little early or late: at most one run of a
// single sample, and the runs' standard deviation within a third of their mean). One block that
// fails ends it, and so does one run far longer than the block's longest (a source that stalled).
// No allocation; O(1) per run.
namespace posefair {

inline constexpr int kRepeatBlockRuns = 32;
inline constexpr int kRepeatBlocks = 2;
// A run's length stops counting here: a source stalled for weeks cannot overflow it.
inline constexpr int kLongestRun = 1 << 30;

class RegularRuns {
 public:
  explicit RegularRuns(double min_mean_run) : min_mean_run_(min_mean_run) {}
  // A run of `length` samples ended.
  void end_run(int length);
  // The current run has `length` samples so far: one far longer than the block's longest ends
  // the regularity at once, not at the block's end.
  void check_open_run(int length);
  // A run that no regular source would make (a kink whose lines do not meet): not regular, and
  // the blocks start again.
  void break_off();
  bool regular() const { return regular_; }

 private:
  double min_mean_run_;
  int runs_ = 0, shortest_ = 0, longest_ = 0;
  long samples_ = 0, squares_ = 0;  // Σ run and Σ run² over this block's runs
  int singles_ = 0;                 // this block's runs of one sample
  int blocks_ = 0;                  // regular blocks in a row
  bool regular_ = false;
};

}  // namespace posefair
