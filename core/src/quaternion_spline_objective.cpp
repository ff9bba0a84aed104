#include "posefair/core/quaternion_spline_objective.hpp"

#include <stdexcept>

#include "posefair/core/covariant_acceleration.hpp"

namespace posefair {

SplineObjective::SplineObjective(double alpha, int quadrature_points)
    : alpha_(alpha), rule_(gauss_legendre_rule(quadrature_points)) {
  if (!(alpha >= 0.0)) throw std::invalid_argument("SplineObjective: alpha must be >= 0");
}

double SplineObjective::value(const HermiteCurve4& curve) const {
  double total = 0.0;
  for (std::size_t i = 0; i < curve.pieces(); ++i) {
    const double h = curve.nodes()[i + 1].time - curve.nodes()[i].time;
    for (std::size_t k = 0; k < rule_.node.size(); ++k) {
      const CurveJet j = curve.jet_on_piece(i, rule_.node[k]);
      total += rule_.weight[k] * h * objective_integrand(j.q, j.d2, alpha_).value;
    }
  }
  return total;
}

double SplineObjective::covariant_part(const HermiteCurve4& curve) const {
  double total = 0.0;
  for (std::size_t i = 0; i < curve.pieces(); ++i) {
    const double h = curve.nodes()[i + 1].time - curve.nodes()[i].time;
    for (std::size_t k = 0; k < rule_.node.size(); ++k) {
      const CurveJet j = curve.jet_on_piece(i, rule_.node[k]);
      total += rule_.weight[k] * h * covariant_acceleration_squared(j.q, j.d2);
    }
  }
  return total;
}

double SplineObjective::value_and_gradient(const HermiteCurve4& curve, ObjectiveGradient& g) const {
  const auto& nodes = curve.nodes();
  g.d_position.assign(nodes.size(), Vec4::Zero());
  g.d_velocity.assign(nodes.size(), Vec4::Zero());
  double total = 0.0;
  for (std::size_t i = 0; i < curve.pieces(); ++i) {
    const double h = nodes[i + 1].time - nodes[i].time;
    Eigen::Matrix4d coeff;  // columns: p0, h·v0, p1, h·v1
    coeff << nodes[i].position, h * nodes[i].velocity, nodes[i + 1].position, h * nodes[i + 1].velocity;
    // ∂OBJ/∂(column c) = Σ_k w_k h (∂F/∂q · B0c + ∂F/∂q″ · B2c / h²)
    Eigen::Matrix4d d_coeff = Eigen::Matrix4d::Zero();
    for (std::size_t k = 0; k < rule_.node.size(); ++k) {
      const Eigen::Matrix4d basis = hermite_basis(rule_.node[k]);
      const Vec4 q = coeff * basis.row(0).transpose();
      const Vec4 q2 = coeff * basis.row(2).transpose() / (h * h);
      const IntegrandPartials p = objective_integrand(q, q2, alpha_);
      const double wh = rule_.weight[k] * h;
      total += wh * p.value;
      d_coeff += wh * (p.d_q * basis.row(0) + p.d_q2 * basis.row(2) / (h * h));
    }
    g.d_position[i] += d_coeff.col(0);
    g.d_velocity[i] += h * d_coeff.col(1);
    g.d_position[i + 1] += d_coeff.col(2);
    g.d_velocity[i + 1] += h * d_coeff.col(3);
  }
  return total;
}

}  // namespace posefair
