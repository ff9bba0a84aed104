#pragma once
// 4x4 affine matrices for the matrix-function and linear-combination tests: built from a linear
// part and a translation, rotations about an axis, and the relative distance between two.
#include <Eigen/Geometry>

#include "posefair/core/matrix_functions.hpp"

namespace posefair::testing {

inline Mat4 affine(const Eigen::Matrix3d& l, const Eigen::Vector3d& t) {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = l;
  m.topRightCorner<3, 1>() = t;
  return m;
}

inline Eigen::Matrix3d rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// |x - ref| / |ref| in the max-row-sum norm.
inline double rel(const Mat4& x, const Mat4& ref) { return norm_inf(x - ref) / norm_inf(ref); }

}  // namespace posefair::testing
