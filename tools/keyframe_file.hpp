#pragma once
// Keyframe files for `posefair spline` (docs/quaternion-splines.md):
//
//   # comment; blank lines are skipped; fields are separated by whitespace and/or commas
//   t w x y z                   5 fields: time (s) and the quaternion, w first
//   t tx ty tz qx qy qz qw      8 fields: a TUM line (w last; the position is ignored)
//   omega_start wx wy wz        optional: angular velocity at the first key (rad/s, spatial frame)
//   omega_end wx wy wz          optional: angular velocity at the last key
//
// Every keyframe line of one file has the same layout. Times must increase strictly,
// quaternions must have | |q| − 1 | <= 1e-3 (they are renormalised), and there must be at least
// two keyframes. Any problem is a formats::PoseFileError "<path>:<line>: <message>"; a file
// that cannot be opened is an Error of kind NoInput (worded the same way).
#include <filesystem>
#include <iosfwd>
#include <string>

#include "posefair/core/quaternion_spline.hpp"

namespace posefair::tools {

inline constexpr double kKeyframeUnitTolerance = 1e-3;

SplineKeyframes parse_keyframes(std::istream& in, const std::string& name);
// Throws formats::PoseFileError (line 0) when the file cannot be opened.
SplineKeyframes read_keyframes(const std::filesystem::path& path);

}  // namespace posefair::tools
