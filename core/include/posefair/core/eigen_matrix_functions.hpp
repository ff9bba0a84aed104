#pragma once
// Eigen's own matrix exponential, logarithm and square root (unsupported/Eigen/MatrixFunctions)
// of a 4x4 matrix: the independent reference that the matrix-function tests, the interpolation
// study and its benchmark hold posefair's matrix_exp/log/sqrt against. Instantiated once, in
// eigen_matrix_functions.cpp, because MatrixFunctions is among the costliest Eigen code to compile.
#include "posefair/core/matrix_functions.hpp"

namespace posefair {

Mat4 eigen_matrix_exp(const Mat4& a);
Mat4 eigen_matrix_log(const Mat4& a);
Mat4 eigen_matrix_sqrt(const Mat4& a);

}  // namespace posefair
