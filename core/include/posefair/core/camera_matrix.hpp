#pragma once
// Camera matrices C = P S R T (Michener & Carlbom, as in Hawkins & Grimm Section 3.1) and their
// interpolation. P (eq. 4) is split as P = P_a P_b (eq. 5): P_a holds only the near/far ratio k
// and is not interpolated (k is interpolated as a number); P_b (aspect, skew, centre of
// projection) is affine with positive eigenvalues and is interpolated with S R T. Each key is
// combined about its view part S R T (eq. 7), so P_b stays in the logarithm.
//
// Conventions: the camera looks down -z of its own frame with +y up; R's rows are the camera's
// right, up and back axes in world coordinates; T translates `from` to the origin;
// S = diag(c/far, c/far, 1/far, 1) with c = cot(fov_y / 2), so the far plane is z = -1 and the
// vertical half-angle maps to slope 1; P_b's alpha scales x (alpha = 1: square pixels in a
// square view). After the divide by w, x and y are in [-1, 1] inside the view.
#include <span>
#include <vector>

#include <Eigen/Core>

#include "posefair/core/keyframe_interpolation.hpp"

namespace posefair {

struct CameraIntrinsics {
  double fov_y = 0.8;   // vertical field of view, radians
  double aspect = 1.0;  // alpha of eq. 4
  double skew = 0.0;    // gamma
  double cop_u = 0.0;   // centre of projection (u0, v0)
  double cop_v = 0.0;
  double near = 0.1;
  double far = 100.0;
};

struct CameraParams {
  Eigen::Vector3d from{0, 0, 1};
  Eigen::Vector3d at{0, 0, 0};
  Eigen::Vector3d up{0, 1, 0};
  CameraIntrinsics lens;
};

// World-to-camera rotation whose rows are right, up and back (from - at normalised). Throws
// std::invalid_argument when from == at or up is parallel to the viewing direction.
Eigen::Matrix3d look_at_rotation(const Eigen::Vector3d& from, const Eigen::Vector3d& at, const Eigen::Vector3d& up);

Mat4 perspective_matrix(const CameraIntrinsics& l);    // P, eq. 4
Mat4 perspective_a(double k);                          // P_a, eq. 5 (k = near / far)
Mat4 perspective_b(const CameraIntrinsics& l);         // P_b, eq. 5
Mat4 view_scale(const CameraIntrinsics& l);            // S
Mat4 view_rotation(const Eigen::Matrix3d& r);          // R
Mat4 view_translation(const Eigen::Vector3d& from);    // T

// The view part S R T for a rotation and position (for parameter interpolation).
Mat4 view_part(const CameraIntrinsics& l, const Eigen::Matrix3d& r, const Eigen::Vector3d& from);
// C = P S R T.
Mat4 camera_matrix(const CameraParams& c);

// What gets interpolated for one key: M = P_b S R T, its origin S R T, and k.
struct CameraKey {
  Mat4 matrix;
  Mat4 origin;
  double k;
};
CameraKey camera_key(const CameraParams& c);
// A key given as the affine matrix M = P_b S R T directly (bottom row 0 0 0 1); its own origin.
CameraKey camera_key(const Mat4& m, double k);

// Camera matrices P_a(k(t)) M(t) at the frame times (k piecewise linear in time).
Result<std::vector<Mat4>> interpolate_cameras(InterpolationMethod method, std::span<const double> key_times,
                                              std::span<const CameraKey> keys, std::span<const double> frame_times,
                                              const CombinationOptions& o = {});

// Camera-parameter interpolation (the paper's baseline): position, Z-Y-X Euler angles of R
// (each along its shorter way round), field of view, aspect, skew, centre of projection and
// near/far, each linearly.
Mat4 camera_parameter_lerp_matrix(const CameraParams& a, const CameraParams& b, double t);
// The same without P_a: P_b S R T of the interpolated parameters, the affine map into camera
// space that matrix interpolation's M(t) corresponds to (Section 5.1 measures there).
Mat4 camera_parameter_lerp_affine(const CameraParams& a, const CameraParams& b, double t);

}  // namespace posefair
