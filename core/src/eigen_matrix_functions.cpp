#include "posefair/core/eigen_matrix_functions.hpp"

#include <complex>
#include <unsupported/Eigen/MatrixFunctions>

namespace posefair {

namespace {

// The logarithm and square root go through Eigen's complex, dynamic-size path. Eigen computes a
// real matrix's logarithm through a complex Schur form anyway, and a real matrix's principal
// square root is the real part of its complex one; the fixed-size real instantiations took
// 50-100 s to compile in each build, these take a few seconds.
using ComplexMatrix = Eigen::MatrixXcd;

ComplexMatrix complex_of(const Mat4& a) { return a.cast<std::complex<double>>(); }

}  // namespace

Mat4 eigen_matrix_exp(const Mat4& a) { return a.exp(); }

Mat4 eigen_matrix_log(const Mat4& a) {
  const ComplexMatrix l = complex_of(a).log();
  return l.real();
}

Mat4 eigen_matrix_sqrt(const Mat4& a) {
  const ComplexMatrix s = complex_of(a).sqrt();
  return s.real();
}

}  // namespace posefair
