#include "posefair/core/linear_combination.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace posefair {
namespace {

MatrixError prefixed(const MatrixError& e, const char* what) { return MatrixError{e.code, std::string(what) + e.message}; }

}  // namespace

double rotational_component(const Mat4& m) {
  const Eigen::Matrix3d l = m.topLeftCorner<3, 3>();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(l, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d u = svd.matrixU() * svd.matrixV().transpose();
  // A reflection (det < 0) has no real logarithm at all: report it as a half turn.
  if (u.determinant() < 0.0) return std::numbers::pi;
  const double c = std::clamp((u.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

MatrixResult scale(double s, const Mat4& a, const CombinationOptions& o) {
  MatrixResult l = matrix_log(a, o.log);
  if (!l) return l;
  return matrix_exp(s * l.value(), o.exp);
}

MatrixResult add(const Mat4& a, const Mat4& b, const CombinationOptions& o) {
  MatrixResult la = matrix_log(a, o.log);
  if (!la) return la;
  MatrixResult lb = matrix_log(b, o.log);
  if (!lb) return lb;
  return matrix_exp(la.value() + lb.value(), o.exp);
}

MatrixResult lerp_direct(const Mat4& a, const Mat4& b, double t, const CombinationOptions& o) {
  MatrixResult la = matrix_log(a, o.log);
  if (!la) return la;
  MatrixResult lb = matrix_log(b, o.log);
  if (!lb) return lb;
  return matrix_exp((1.0 - t) * la.value() + t * lb.value(), o.exp);
}

MatrixResult log_about(const Mat4& m, const Mat4& x, const CombinationOptions& o) {
  const Mat4 rel = m * x.inverse();
  if (!rel.allFinite()) return MatrixError{MatrixErrorCode::NotFinite, "the origin transform is singular"};
  const double angle = rotational_component(rel);
  if (angle >= o.max_step_angle) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "the keyframes are %.1f degrees apart in rotation (at or above %.1f): add a keyframe in between",
                  angle * 180.0 / std::numbers::pi, o.max_step_angle * 180.0 / std::numbers::pi);
    return MatrixError{MatrixErrorCode::UnsafeStep, buf};
  }
  // The origin itself: log I = 0 exactly, no iteration needed.
  if ((rel - Mat4::Identity()).cwiseAbs().maxCoeff() == 0.0) return Mat4(Mat4::Zero());
  return matrix_log(rel, o.log);
}

Result<PreparedLerp> PreparedLerp::make(const Mat4& a, const Mat4& b, const Mat4& x, const CombinationOptions& o) {
  MatrixResult la = log_about(a, x, o);
  if (!la) return prefixed(la.error(), "first keyframe: ");
  MatrixResult lb = log_about(b, x, o);
  if (!lb) return prefixed(lb.error(), "second keyframe: ");
  return PreparedLerp(la.value(), lb.value(), x, o.exp);
}

MatrixResult PreparedLerp::at(double t) const {
  MatrixResult e = matrix_exp((1.0 - t) * log_a_ + t * log_b_, exp_);
  if (!e) return e;
  return Mat4(e.value() * origin_);
}

MatrixResult lerp(const Mat4& a, const Mat4& b, double t, const CombinationOptions& o) {
  Result<PreparedLerp> p = PreparedLerp::make(a, b, o);
  if (!p) return p.error();
  return p.value().at(t);
}

MatrixResult combine(std::span<const double> weights, std::span<const Mat4> matrices, const Mat4& x,
                     const CombinationOptions& o) {
  Mat4 sum = Mat4::Zero();
  for (std::size_t i = 0; i < weights.size() && i < matrices.size(); ++i) {
    if (weights[i] == 0.0) continue;
    MatrixResult l = log_about(matrices[i], x, o);
    if (!l) return l;
    sum += weights[i] * l.value();
  }
  MatrixResult e = matrix_exp(sum, o.exp);
  if (!e) return e;
  return Mat4(e.value() * x);
}

}  // namespace posefair
