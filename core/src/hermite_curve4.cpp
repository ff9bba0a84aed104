#include "posefair/core/hermite_curve4.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace posefair {

Eigen::Matrix4d hermite_basis(double s) {
  const double s2 = s * s, s3 = s2 * s;
  Eigen::Matrix4d b;
  b << 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2,  //
      6 * s2 - 6 * s, 3 * s2 - 4 * s + 1, -6 * s2 + 6 * s, 3 * s2 - 2 * s,  //
      12 * s - 6, 6 * s - 4, -12 * s + 6, 6 * s - 2,                        //
      12, 6, -12, 6;
  return b;
}

HermiteCurve4::HermiteCurve4(std::vector<HermiteNode> nodes) : nodes_(std::move(nodes)) {
  if (nodes_.size() < 2) throw std::invalid_argument("HermiteCurve4: need at least two nodes");
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (!std::isfinite(nodes_[i].time)) throw std::invalid_argument("HermiteCurve4: non-finite node time");
    if (i > 0 && !(nodes_[i].time > nodes_[i - 1].time))
      throw std::invalid_argument("HermiteCurve4: node times must increase strictly");
  }
}

std::size_t HermiteCurve4::piece_at(double t) const {
  // First node with time > t, minus one, clamped to a valid piece.
  const auto it = std::upper_bound(nodes_.begin(), nodes_.end(), t,
                                   [](double x, const HermiteNode& n) { return x < n.time; });
  const auto i = static_cast<std::ptrdiff_t>(it - nodes_.begin()) - 1;
  return static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(i, 0, static_cast<std::ptrdiff_t>(pieces()) - 1));
}

CurveJet HermiteCurve4::jet_on_piece(std::size_t piece, double s) const {
  const HermiteNode& a = nodes_[piece];
  const HermiteNode& b = nodes_[piece + 1];
  const double h = b.time - a.time;
  Eigen::Matrix4d coeff;  // columns: p0, h·v0, p1, h·v1
  coeff.col(0) = a.position;
  coeff.col(1) = h * a.velocity;
  coeff.col(2) = b.position;
  coeff.col(3) = h * b.velocity;
  const Eigen::Matrix4d basis = hermite_basis(s);
  CurveJet j;
  j.q = coeff * basis.row(0).transpose();
  j.d1 = coeff * basis.row(1).transpose() / h;
  j.d2 = coeff * basis.row(2).transpose() / (h * h);
  j.d3 = coeff * basis.row(3).transpose() / (h * h * h);
  return j;
}

CurveJet HermiteCurve4::jet(double t) const {
  const std::size_t i = piece_at(t);
  const double h = nodes_[i + 1].time - nodes_[i].time;
  return jet_on_piece(i, (t - nodes_[i].time) / h);
}

std::size_t HermiteCurve4::split_at(double t) {
  const std::size_t i = piece_at(t);
  if (!(t > nodes_[i].time && t < nodes_[i + 1].time))
    throw std::invalid_argument("HermiteCurve4::split_at: time must lie strictly inside a piece");
  const CurveJet j = jet(t);
  HermiteNode n;
  n.time = t;
  n.position = j.q;
  n.velocity = j.d1;
  nodes_.insert(nodes_.begin() + static_cast<std::ptrdiff_t>(i) + 1, n);
  return i + 1;
}

}  // namespace posefair
