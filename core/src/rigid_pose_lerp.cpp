#include "posefair/core/rigid_pose_lerp.hpp"

#include <cmath>

namespace posefair {
namespace {

Mat4 rigid(const Quat& q, const Vec3& p) {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = q.toRotationMatrix();
  m.topRightCorner<3, 1>() = p;
  return m;
}

// Refuse a little below max_step_angle: lerp measures the angle its own way (an SVD), and a
// refusal there would build an error message (an allocation) on the engine thread.
constexpr double kAngleMargin = 1e-9;

}  // namespace

bool RigidPoseLerp::prepare(const Quat& qa, const Vec3& pa, const Quat& qb, const Vec3& pb) {
  qa_ = qa.normalized();
  qb_ = so3::aligned_to(qb.normalized(), qa_);
  pa_ = pa;
  pb_ = pb;
  lerp_.reset();
  if (!pa.allFinite() || !pb.allFinite() || !qa_.coeffs().allFinite() || !qb_.coeffs().allFinite() ||
      so3::rotation_angle(qa_, qb_) >= options_.max_step_angle - kAngleMargin) {
    ++fallbacks_;
    return false;
  }
  // Centred on a's position: lerp commutes with a fixed change of world frame, and the
  // logarithm then sees the step (pb - pa), not coordinates far from the origin.
  Result<PreparedLerp> l = PreparedLerp::make(rigid(qa_, Vec3::Zero()), rigid(qb_, pb - pa), options_);
  if (!l) {
    ++fallbacks_;
    return false;
  }
  lerp_.emplace(l.value());
  return true;
}

void RigidPoseLerp::at(double t, Quat& q, Vec3& p) {
  if (lerp_) {
    const MatrixResult m = lerp_->at(t);
    if (m.ok()) {
      q = so3::aligned_to(Quat(Eigen::Matrix3d(m.value().topLeftCorner<3, 3>())).normalized(), qa_);
      p = pa_ + m.value().topRightCorner<3, 1>();
      return;
    }
    ++fallbacks_;
  }
  q = so3::slerp(t, qa_, qb_);
  p = pa_ + t * (pb_ - pa_);
}

}  // namespace posefair
