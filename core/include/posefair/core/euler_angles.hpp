#pragma once
// Euler angles as BVH uses them: angles in degrees about the joint's local X, Y, Z axes,
// composed in the order given, R = R_axes[0](a0) · R_axes[1](a1) · R_axes[2](a2).
#include <array>
#include <optional>
#include <span>
#include <string_view>

#include "posefair/core/so3.hpp"

namespace posefair {

enum class Axis { X = 0, Y = 1, Z = 2 };

// 'X'/'Y'/'Z' (either case) -> Axis.
std::optional<Axis> axis_from_char(char c);

// The rotation R_axes[0](deg[0]) · R_axes[1](deg[1]) · ... as a unit quaternion.
// Any number of elementary rotations; axes and degrees must have the same size.
Quat euler_to_quat(std::span<const Axis> axes, std::span<const double> degrees);

// The Tait–Bryan angles (three distinct axes) of q in that order, choosing among the
// equivalent solutions the one closest to `reference` (degrees): both Tait–Bryan solutions
// (b and 180° - b), each angle unwrapped by multiples of 360° toward the reference, and at
// gimbal lock the split of the free angle that keeps the first (or last) angle at its
// reference. euler_to_quat(axes, result) is q (up to sign) to rounding.
// Throws std::invalid_argument unless the three axes are distinct.
std::array<double, 3> quat_to_euler_nearest(const Quat& q, const std::array<Axis, 3>& axes,
                                            const std::array<double, 3>& reference);

}  // namespace posefair
