#pragma once
// Output-rate resampling (docs/splines.md, "In the daemon"): a faired stream at its input rate
// in, poses on a fixed time grid out (a 100 Hz IMU published at 250 Hz, or at a display's
// 90 Hz), interpolated with the C^k geometric spline through the faired poses.
//
// The grid is t = k / rate_hz on the stream's own clock, so streams at one rate share their
// grid times. The faired poses are placed at the times their samples were taken
// (sampled_clock.hpp): for samples stamped in clumps, an interval apart up to the newest
// one's stamp, not the stamps. A grid pose is final once the spline around it is: the newest faired pose's time
// minus at most (lookahead + 1) input intervals, which is the delay resampling adds; the poses
// carry their grid time, so a subscriber sees it as sent - t. A step longer than max_step
// between faired poses (the window restarted after a gap) restarts the spline: no grid pose is
// made across it. When a stream ends, its last grid poses (up to lookahead + 1 input intervals)
// are not made: the spline there is not final. No allocation after construction.
//
// With PoseInterpolation::MatrixLerp a grid pose is Alexa's lerp of the two faired poses
// around it (rigid_pose_lerp.hpp), prepared once per input interval: it is final when the
// faired pose after it arrives, so the added delay is at most one input interval, and a
// stream's grid poses up to its last faired pose are all made.
#include <cstddef>
#include <cstdint>
#include <span>

#include "posefair/core/pose_spline.hpp"
#include "posefair/core/pose_spline_window.hpp"
#include "posefair/core/rigid_pose_lerp.hpp"
#include "posefair/core/sample.hpp"
#include "posefair/core/sampled_clock.hpp"

namespace posefair {

struct FixedRateResamplerOptions {
  double rate_hz = 250.0;  // > 0
  double max_step = 0.25;  // s: a longer step between faired poses restarts; > 0
  geometric_splines::PoseSplineOptions spline;  // for PoseInterpolation::Spline
  PoseInterpolation interpolation = PoseInterpolation::Spline;
};

class FixedRateResampler {
 public:
  // Throws std::invalid_argument for bad options.
  explicit FixedRateResampler(const FixedRateResamplerOptions& options);

  // Feeds one faired pose (a pose stamped not after the previous one is ignored); writes the grid
  // poses now final to out (at least max_outputs() long) and returns how many. A grid pose is
  // kBridged or kHeld (kNotMeasured) when either faired pose around it is, and has a position
  // when both have one.
  std::size_t push(const FairedPose& pose, std::span<FairedPose> out);
  std::size_t max_outputs() const { return max_outputs_; }
  // The most input intervals a grid pose waits for (the added delay in intervals).
  std::size_t delay_intervals() const {
    return options_.interpolation == PoseInterpolation::MatrixLerp ? 1 : spline_.lookahead() + 1;
  }
  std::uint64_t restarts() const { return restarts_; }
  // MatrixLerp: input intervals lerp refused (a step of pi/2 or more), interpolated separately.
  std::uint64_t lerp_fallbacks() const { return lerp_.fallbacks(); }

 private:
  static constexpr std::size_t kFlagSlots = 16;  // (time, flags) of the newest faired poses

  std::uint32_t flags_between(double t) const;
  std::size_t push_lerp(const FairedPose& pose, std::span<FairedPose> out);

  FixedRateResamplerOptions options_;
  geometric_splines::PoseSplineWindow spline_;
  RigidPoseLerp lerp_;
  std::size_t max_outputs_;
  SampledClock clock_;
  bool have_stamp_ = false;
  double last_stamp_ = 0.0;
  bool have_last_ = false;
  double last_time_ = 0.0;  // on the sampled clock
  std::int64_t next_ = 0;  // index of the next grid time
  FairedPose last_;
  double period_;
  double slot_time_[kFlagSlots] = {};
  std::uint32_t slot_flags_[kFlagSlots] = {};
  std::size_t slots_ = 0;  // poses recorded so far (the newest at (slots_ - 1) % kFlagSlots)
  std::uint64_t restarts_ = 0;
};

}  // namespace posefair
