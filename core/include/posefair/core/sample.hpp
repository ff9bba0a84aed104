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
  // Raw inertial readings (issue 17), in the sensor's own frame, SI units. A sample may carry
  // them beside a measured orientation (gyro-aided fairing) or alone (kNoOrientation: the
  // orientation field is not a measurement, and a fusion stage must make one first).
  kHasGyro = 1u << 4,        // gyro, rad/s
  kHasAccel = 1u << 5,       // accel, m/s^2 (specific force: +g upwards at rest)
  kHasMag = 1u << 6,         // mag, microtesla
  kNoOrientation = 1u << 7,  // raw inertial sample only
  kHeld = 1u << 8,  // FairedPose only: its measurement was an outlier, held at the prediction (outlier_guard.hpp)
};
// A pose not faired from its own measurement: bridged across a gap, or held at the prediction.
// On the wire both are the flag `bridged` (docs/protocol.md).
inline constexpr std::uint32_t kNotMeasured = kBridged | kHeld;

struct Sample {
  std::uint32_t stream_id = 0;
  std::uint64_t sequence = 0;   // per stream, as the driver counted it
  double time = 0.0;            // seconds: the time the engine orders and spaces samples by
  double device_time = 0.0;     // seconds, valid with kHasDeviceTime
  double receive_time = 0.0;    // seconds, CLOCK_MONOTONIC at the read that completed the sample
  Quat orientation = Quat::Identity();
  Vec3 position = Vec3::Zero(); // valid with kHasPosition
  Vec3 gyro = Vec3::Zero();     // rad/s, valid with kHasGyro
  Vec3 accel = Vec3::Zero();    // m/s^2, valid with kHasAccel
  Vec3 mag = Vec3::Zero();      // microtesla, valid with kHasMag
  std::uint32_t flags = 0;

  bool has_position() const { return (flags & kHasPosition) != 0; }
  bool has_orientation() const { return (flags & kNoOrientation) == 0; }
  bool has_gyro() const { return (flags & kHasGyro) != 0; }
  bool has_accel() const { return (flags & kHasAccel) != 0; }
  bool has_mag() const { return (flags & kHasMag) != 0; }
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
  // How long after the previous pose's sample this one's was taken (SampleGate::sampled_step):
  // the stamped step, but one interval for a sample stamped in a clump; 0 for a stream's first.
  double step = 0.0;
};

}  // namespace posefair
