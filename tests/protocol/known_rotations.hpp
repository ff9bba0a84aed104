#pragma once
// The known rotations the client encodings' tests put through every encoding (docs/outputs.md,
// "Frames"), in posefair's frame: x forward, y left, z up. A turn to the left is +z, a pitch up
// (nose up) -y, a lean to the right +x.
#include <cstdint>
#include <numbers>
#include <optional>

#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::testing {

inline constexpr double kDeg = std::numbers::pi / 180.0;

inline Quat turn_left(double degrees) { return Quat(Eigen::AngleAxisd(degrees * kDeg, Vec3::UnitZ())); }
inline Quat pitch_up(double degrees) { return Quat(Eigen::AngleAxisd(-degrees * kDeg, Vec3::UnitY())); }
inline Quat lean_right(double degrees) { return Quat(Eigen::AngleAxisd(degrees * kDeg, Vec3::UnitX())); }

// A pose of `stream` at sample time `time`.
inline daemon::PoseMessage pose(const Quat& q, std::optional<Vec3> p = std::nullopt, std::uint32_t stream = 1, double time = 12.5) {
  daemon::PoseMessage m;
  m.stream = stream;
  m.sample_time = time;
  m.orientation = q;
  m.position = p;
  return m;
}

}  // namespace posefair::testing
