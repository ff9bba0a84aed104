#pragma once
// The reproduction example of docs/quaternion-splines.md, built like the paper's Section 4
// case (its keyframe values are not printed): 7 keyframes one second apart whose z component
// is always zero (so the path stays on a 2-sphere of S³), with zero angular velocity at both ends.
#include "posefair/core/quaternion_spline.hpp"

namespace posefair {

inline SplineKeyframes seven_keyframe_example() {
  SplineKeyframes k;
  k.time = {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
  // (w, x, y, 0), normalised by initial_spline; neighbours are 40°–75° apart on S³.
  k.orientation = {Quat(1.0, 0.0, 0.0, 0.0),  Quat(0.7, 0.7, 0.1, 0.0),  Quat(0.1, 0.9, 0.4, 0.0),
                   Quat(-0.3, 0.5, 0.8, 0.0), Quat(0.2, 0.0, 1.0, 0.0),  Quat(0.7, -0.3, 0.6, 0.0),
                   Quat(0.9, -0.4, -0.1, 0.0)};
  for (Quat& q : k.orientation) q.normalize();
  k.omega_start = Vec3::Zero();
  k.omega_end = Vec3::Zero();
  return k;
}

}  // namespace posefair
