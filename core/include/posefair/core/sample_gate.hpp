#pragma once
// What the engine lets in. Every sample is checked before it reaches a fairing window:
//   - NaN/Inf anywhere, or a zero quaternion: rejected;
//   - |‖q‖ − 1| ≤ unit_tolerance: renormalised (counted); beyond it: rejected;
//   - time not after the last accepted sample's: dropped (repeated or out of order; an
//     older sample cannot be placed in a window that has moved on);
//   - time more than gap_threshold after the last accepted sample, or more than
//     gap_intervals of the stream's sample interval once that is known: accepted, and the
//     window must restart (the operators assume evenly spaced samples; a 100 ms dropout in a
//     285 Hz stream is 28 missing samples, not one long step).
// Sample times may jitter: the fairing operators treat consecutive samples as evenly spaced.
// They may also come in clumps (several samples read together and stamped together): the
// step after a clump only catches up with the samples that came ahead of one per interval,
// and only what it takes beyond that counts against gap_intervals.
#include <cstdint>
#include <limits>

#include "posefair/core/sample.hpp"

namespace posefair {

struct GateConfig {
  double unit_tolerance = 0.01;
  double gap_threshold = 0.25;  // seconds
  double gap_intervals = 4.0;   // a step this many sample intervals long is a gap too (0: off)
};

enum class GateVerdict {
  Accept,
  AcceptAfterGap,     // accept, but restart the window first
  RejectNonFinite,
  RejectZero,
  RejectNonUnit,
  DropRepeated,       // same time as the last accepted sample
  DropOutOfOrder,     // older than the last accepted sample
};

struct GateCounters {
  std::uint64_t accepted = 0;
  std::uint64_t renormalised = 0;
  std::uint64_t rejected_non_finite = 0;
  std::uint64_t rejected_zero = 0;
  std::uint64_t rejected_non_unit = 0;
  std::uint64_t dropped_repeated = 0;
  std::uint64_t dropped_out_of_order = 0;
  std::uint64_t gaps = 0;

  std::uint64_t rejected() const { return rejected_non_finite + rejected_zero + rejected_non_unit; }
  std::uint64_t dropped() const { return dropped_repeated + dropped_out_of_order; }
};

class SampleGate {
 public:
  explicit SampleGate(const GateConfig& config = {});
  // Checks s; on acceptance its orientation is normalised in place.
  GateVerdict check(Sample& s);
  // Whether s could be accepted at all, its time aside: Accept, or the reject check() would give
  // (nothing counted).
  GateVerdict validity(const Sample& s) const;
  // Forget the last time (a new stream), keep the counters.
  void restart() {
    last_time_ = -std::numeric_limits<double>::infinity();
    ahead_ = 0.0;
    sampled_step_ = 0.0;
  }
  const GateCounters& counters() const { return counters_; }
  const GateConfig& config() const { return config_; }
  // The stream's sample interval (seconds), once known: a step longer than gap_intervals of
  // it, beyond what catches up with a clump, is a gap as well.
  void set_interval(double interval);
  // How long after the previous accepted sample the last one was taken, as far as the stamps
  // tell: inside a clump (a step under half the interval) or after one, its stamped step less
  // what that catches up, and at least the interval; otherwise (and after a gap, or while the
  // interval is unknown) the stamped step; 0 for the first sample.
  double sampled_step() const { return sampled_step_; }

 private:
  GateConfig config_;
  double interval_ = 0.0;  // 0: unknown, or gap_intervals off
  // How far the samples since the last gap have come ahead of one per interval (a clump).
  double ahead_ = 0.0;
  double sampled_step_ = 0.0;
  GateCounters counters_;
  double last_time_ = -std::numeric_limits<double>::infinity();
};

}  // namespace posefair
