#pragma once
// A C¹ piecewise cubic Hermite curve in R⁴, used for quaternion paths (components w, x, y, z;
// the curve is not constrained to the unit sphere). Each node fixes the position and the
// velocity at its time; between two nodes the curve is the one cubic matching both ends
// (Ramamoorthi & Barr, step 2).
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace posefair {

using Vec4 = Eigen::Vector4d;

struct HermiteNode {
  double time = 0.0;
  Vec4 position = Vec4::Zero();
  Vec4 velocity = Vec4::Zero();  // d/dt, per second
};

// q and its first four time derivatives at one time (d4 is zero on a cubic; it is here so the
// same type describes any smooth path, e.g. an exact great circle in a test).
struct CurveJet {
  Vec4 q = Vec4::Zero(), d1 = Vec4::Zero(), d2 = Vec4::Zero(), d3 = Vec4::Zero(), d4 = Vec4::Zero();
};

// The cubic Hermite basis at s in [0, 1]: row k holds the k-th s-derivative (k = 0..3) of
// (h00, h10, h01, h11), the weights of p0, (h·v0), p1, (h·v1).
Eigen::Matrix4d hermite_basis(double s);

class HermiteCurve4 {
 public:
  HermiteCurve4() = default;
  // At least two nodes with strictly increasing finite times (std::invalid_argument otherwise).
  explicit HermiteCurve4(std::vector<HermiteNode> nodes);

  // Positions and velocities may be changed in place; times must stay strictly increasing.
  const std::vector<HermiteNode>& nodes() const { return nodes_; }
  std::vector<HermiteNode>& nodes() { return nodes_; }
  std::size_t pieces() const { return nodes_.size() - 1; }
  double start_time() const { return nodes_.front().time; }
  double end_time() const { return nodes_.back().time; }

  // The piece [t_i, t_i+1] holding t (times outside the curve go to the first or last piece).
  std::size_t piece_at(double t) const;
  // q and its derivatives on piece i at local parameter s in [0, 1].
  CurveJet jet_on_piece(std::size_t piece, double s) const;
  CurveJet jet(double t) const;
  Vec4 position(double t) const { return jet(t).q; }

  // Adds a node at t, strictly between two existing nodes, carrying the curve's own position and
  // velocity there, so the curve is unchanged (a cubic split in two is the same two cubics).
  // Returns the new node's index.
  std::size_t split_at(double t);

 private:
  std::vector<HermiteNode> nodes_;
};

}  // namespace posefair
