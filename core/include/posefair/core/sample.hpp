#pragma once
// The one sample type that crosses every boundary (DESIGN.md, data flow): a driver makes it,
// the engine consumes it, the recorder stores it. Nothing downstream knows which bus it came from.
#include <cstdint>

#include "posefair/core/so3.hpp"

namespace posefair {

enum SampleFlags : std::uint32_t {
  kHasPosition = 1u << 0,
  kHasDeviceTime = 1u << 1,
  kClamped = 1u << 2,  // FairedPose only: the ε projection moved this pose (it sits on its bound)
  kBridged = 1u << 3,  // made on a spline across a gap in the input (gap_bridge.hpp), not measured
};

struct Sample {
  std::uint32_t stream_id = 0;
  std::uint64_t sequence = 0;   // per stream, as the driver counted it
  double time = 0.0;            // seconds: the time the engine orders and spaces samples by
  double device_time = 0.0;     // seconds, valid with kHasDeviceTime
  double receive_time = 0.0;    // seconds, CLOCK_MONOTONIC at the read that completed the sample
  Quat orientation = Quat::Identity();
  Vec3 position = Vec3::Zero(); // valid with kHasPosition
  std::uint32_t flags = 0;

  bool has_position() const { return (flags & kHasPosition) != 0; }
};

// A faired pose leaving the engine: the sample's own time and identity, the faired values,
// and what the sensor measured (for the ε promise and for callers that compare).
struct FairedPose {
  std::uint32_t stream_id = 0;
  std::uint64_t sequence = 0;
  double time = 0.0;
  Quat orientation = Quat::Identity();  // hemisphere-continuous along the stream
  Vec3 position = Vec3::Zero();
  Quat measured = Quat::Identity();     // the input as given (its own sign), normalised
  Vec3 measured_position = Vec3::Zero();
  std::uint32_t flags = 0;              // the sample's flags, plus kClamped
};

}  // namespace posefair
