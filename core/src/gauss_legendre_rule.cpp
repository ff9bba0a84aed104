#include "posefair/core/gauss_legendre_rule.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace posefair {

QuadratureRule gauss_legendre_rule(int n) {
  if (n < 1) throw std::invalid_argument("gauss_legendre_rule: need at least one node");
  // Legendre three-term recurrence: symmetric tridiagonal with off-diagonals k / sqrt(4k² − 1).
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) {
    const double beta = k / std::sqrt(4.0 * k * k - 1.0);
    jacobi(k, k - 1) = jacobi(k - 1, k) = beta;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jacobi);
  QuadratureRule rule;
  rule.node.resize(n);
  rule.weight.resize(n);
  for (int i = 0; i < n; ++i) {
    // Nodes on [−1, 1] map to (x + 1)/2; the weight on [−1, 1] is 2 v₀², halved for [0, 1].
    rule.node[i] = 0.5 * (eig.eigenvalues()(i) + 1.0);
    const double v0 = eig.eigenvectors()(0, i);
    rule.weight[i] = v0 * v0;
  }
  return rule;
}

}  // namespace posefair
