#pragma once
// Unit-quaternion geometry in the convention of all the source papers (see docs/fairing.md):
//   exp(v) = (cos|v|, v/|v| sin|v|), so exp(v) rotates by 2|v|  ("half-angle" convention),
//   log(q) is its inverse on |v| <= pi/2 after choosing the hemisphere w >= 0.
// Users think in physical rotation angles; convert only at the edges with
// from_rotation_vector / to_rotation_vector / rotation_angle.
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace posefair {

using Quat = Eigen::Quaterniond;  // Eigen stores (x, y, z, w); construct as Quat(w, x, y, z)
using Vec3 = Eigen::Vector3d;

namespace so3 {

// exp(v) = (cos|v|, v̂ sin|v|); exact unit norm to rounding for every v, including |v| -> 0.
Quat exp(const Vec3& v);

// Inverse of exp on the hemisphere w >= 0: |log(q)| <= pi/2. Accepts any non-zero q
// (its norm does not change the result); q and -q give the same log.
Vec3 log(const Quat& q);

// Geodesic interpolation a·exp(t·log(a⁻¹b)) along the shorter arc (b and -b are one rotation).
Quat slerp(double t, const Quat& a, const Quat& b);

// Lee & Shin eq. 19: the angle on S³ between the rotations a and b, in [0, pi/2].
// It is half the physical rotation angle between them.
double dist(const Quat& a, const Quat& b);

// Physical rotation angle between a and b in [0, pi] (= 2 · dist).
inline double rotation_angle(const Quat& a, const Quat& b) { return 2.0 * dist(a, b); }

// Edge conversions: a rotation vector (axis times physical angle, radians) <-> quaternion.
inline Quat from_rotation_vector(const Vec3& r) { return exp(0.5 * r); }
inline Vec3 to_rotation_vector(const Quat& q) { return 2.0 * log(q); }

// q or -q, whichever lies in the hemisphere of ref (q·ref >= 0).
inline Quat aligned_to(const Quat& q, const Quat& ref) {
  return q.dot(ref) < 0.0 ? Quat(-q.coeffs()) : q;
}

// Hemisphere continuity: the first sample is put in w >= 0, every later one in the hemisphere
// of its predecessor, so consecutive samples are never more than pi/2 apart on S³.
// The result depends only on the rotations, not on the signs the input had.
void make_continuous(std::span<Quat> q);

}  // namespace so3
}  // namespace posefair
