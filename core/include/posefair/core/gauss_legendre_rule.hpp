#pragma once
// Gauss–Legendre quadrature on [0, 1]: n nodes integrate polynomials of degree 2n − 1 exactly.
#include <vector>

namespace posefair {

struct QuadratureRule {
  std::vector<double> node;    // in (0, 1), increasing
  std::vector<double> weight;  // positive, summing to 1
};

// The n-point rule (n >= 1), from the eigen-decomposition of the Jacobi matrix (Golub–Welsch).
QuadratureRule gauss_legendre_rule(int n);

}  // namespace posefair
