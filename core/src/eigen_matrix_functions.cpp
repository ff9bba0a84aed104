#include "posefair/core/eigen_matrix_functions.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace posefair {

Mat4 eigen_matrix_exp(const Mat4& a) { return a.exp(); }
Mat4 eigen_matrix_log(const Mat4& a) { return a.log(); }
Mat4 eigen_matrix_sqrt(const Mat4& a) { return a.sqrt(); }

}  // namespace posefair
