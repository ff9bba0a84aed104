#pragma once
// Gap bridging (docs/splines.md, "In the daemon"): a short dropout in a live stream is filled
// with samples on the C^k geometric spline through the samples around it, at the stream's own
// interval, so the fairing window sees a regular stream instead of restarting. Longer gaps
// pass through unchanged (the window then restarts, as without bridging).
//
// The spline's velocity at the first sample after the gap needs the sample after that, so that
// sample is held until its successor arrives: a gap costs one input interval of extra delay,
// once. Bridged samples carry kBridged. No allocation after construction.
//
// With PoseInterpolation::MatrixLerp the gap is filled with Alexa's lerp of the two samples
// around it (rigid_pose_lerp.hpp) as soon as the sample after it arrives: nothing is held.
//
// Samples read in a clump (stamped µs apart, kClumpStampStep) pass through: the first of each
// clump is the knot and sets the interval, so the pause after a clump is no gap, and a gap is
// bridged at the read's period. After a gap the rest of the first read waits with its first
// sample for the next read (whose first sample is the knot the spline's velocity needs): a
// read's period of delay, once; more than kClumpHeld samples in a read and the gap is passed
// through (counted: clumped).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "posefair/core/pose_spline.hpp"
#include "posefair/core/pose_spline_window.hpp"
#include "posefair/core/rigid_pose_lerp.hpp"
#include "posefair/core/sample.hpp"

namespace posefair {

struct GapBridgeOptions {
  double max_gap = 0.2;             // s: the longest gap bridged; > 0
  std::size_t max_bridged = 256;    // samples per gap at most (a longer gap gets a coarser step); >= 1
  geometric_splines::PoseSplineOptions spline;
  PoseInterpolation interpolation = PoseInterpolation::Spline;
};

struct GapBridgeCounters {
  std::uint64_t gaps = 0;      // gaps bridged
  std::uint64_t samples = 0;   // samples made on the spline
  std::uint64_t too_long = 0;  // gaps longer than max_gap, passed through
  std::uint64_t clumped = 0;   // gaps ended by a read of more than kClumpHeld samples, passed through
  std::uint64_t lerp_fallbacks = 0;  // MatrixLerp: gaps lerp refused (a step of pi/2 or more), bridged separately
};

class GapBridge {
 public:
  // Throws std::invalid_argument for bad options.
  explicit GapBridge(const GapBridgeOptions& options);

  // Feeds one sample; writes the samples to hand on, in order, to out (at least max_outputs()
  // long) and returns how many: usually the sample itself; none while the first sample after a
  // gap (and its read's next ones) wait for its successor; then the bridged samples, the held
  // ones and this one.
  std::size_t push(const Sample& s, std::span<Sample> out);
  // The stream ended: the held sample and the samples of its read waiting with it, if any (not
  // bridged: its velocity is not final).
  std::size_t flush(std::span<Sample> out);
  std::size_t max_outputs() const { return options_.max_bridged + 2 + kClumpHeld; }
  static constexpr std::size_t kClumpHeld = 32;  // samples of a read that wait with a held one
  const GapBridgeCounters& counters() const { return counters_; }

 private:
  std::size_t release(const Sample& current, std::span<Sample> out);
  std::size_t hand_on_held(std::span<Sample> out);
  std::size_t lerp_across(const Sample& after, std::span<Sample> out);

  GapBridgeOptions options_;
  geometric_splines::PoseSplineWindow spline_;
  RigidPoseLerp lerp_;
  GapBridgeCounters counters_;
  double last_time_ = 0.0;      // of the newest sample handed on or held
  double interval_ = 0.0;       // the stream's regular interval (last step that was not a gap); 0 = unknown
  bool have_last_ = false;
  bool holding_ = false;
  Sample held_;
  std::array<Sample, kClumpHeld> clump_{};  // the held sample's read, after it
  std::size_t clump_count_ = 0;
  Sample before_;               // the last sample before the gap
};

}  // namespace posefair
