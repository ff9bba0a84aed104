#include "posefair/core/matrix_functions.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace posefair {
namespace {

MatrixError error(MatrixErrorCode code, const char* fmt, double a = 0.0, double b = 0.0, double c = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return MatrixError{code, buf};
}

// The iteration of Figure 3(b) without the eigenvalue check (the logarithm checks once and then
// takes square roots of matrices that are known to have a principal square root).
MatrixResult sqrt_iteration(const Mat4& a, const SqrtOptions& o, SqrtTrace* trace) {
  Mat4 x = a;
  Mat4 y = Mat4::Identity();
  const double tolerance = o.relative ? o.epsilon * norm_inf(a) : o.epsilon;
  for (int it = 0;; ++it) {
    const double residual = norm_inf(x * x - a);
    if (trace) {
      trace->iterations = it;
      trace->residuals.push_back(residual);
    }
    if (!std::isfinite(residual))
      return error(MatrixErrorCode::NotFinite, "square root: the iteration diverged to non-finite values after %g updates", it);
    if (residual < tolerance) return x;
    if (it == o.max_iterations)
      return error(MatrixErrorCode::NoConvergence,
                   "square root: no convergence in %g iterations (|XX - A| = %.3g > eps3 = %.3g); add a keyframe",
                   it, residual, o.epsilon);
    const Mat4 x_inv = x.inverse();
    x = 0.5 * (x + y.inverse());
    y = 0.5 * (y + x_inv);
  }
}

bool all_finite(const Mat4& a) { return a.allFinite(); }

}  // namespace

MatrixResult denman_beavers_sqrt(const Mat4& a, const SqrtOptions& o, SqrtTrace* trace) {
  if (!all_finite(a)) return error(MatrixErrorCode::NotFinite, "square root: the matrix has nan or inf entries");
  return sqrt_iteration(a, o, trace);
}

const char* to_string(MatrixErrorCode c) {
  switch (c) {
    case MatrixErrorCode::NoPrincipalLogarithm: return "no principal real logarithm";
    case MatrixErrorCode::NoConvergence: return "no convergence";
    case MatrixErrorCode::NotFinite: return "not finite";
    case MatrixErrorCode::UnsafeStep: return "unsafe step";
  }
  return "?";
}

double norm_inf(const Mat4& a) { return a.cwiseAbs().rowwise().sum().maxCoeff(); }

MatrixResult matrix_exp(const Mat4& a_in, const ExpOptions& o) {
  if (!all_finite(a_in)) return error(MatrixErrorCode::NotFinite, "exponential: the matrix has nan or inf entries");
  const double n = norm_inf(a_in);
  // ERRATA item 2: the scaling exponent is an integer, j = max(0, 1 + floor(log2 |A|)).
  const int j = n > 0.0 ? std::max(0, 1 + static_cast<int>(std::floor(std::log2(n)))) : 0;
  const Mat4 a = std::ldexp(1.0, -j) * a_in;
  const int q = o.pade_degree;
  Mat4 d = Mat4::Identity(), num = Mat4::Identity(), x = Mat4::Identity();
  double c = 1.0;
  for (int k = 1; k <= q; ++k) {
    c = c * (q - k + 1) / (k * (2.0 * q - k + 1));
    x = a * x;
    num += c * x;
    d += (k % 2 == 0 ? c : -c) * x;
  }
  x = d.partialPivLu().solve(num);
  for (int i = 0; i < j; ++i) x = x * x;
  if (!all_finite(x))
    return error(MatrixErrorCode::NotFinite, "exponential: overflow (|A| = %.3g, %g squarings)", n, j);
  return x;
}

std::variant<std::monostate, MatrixError> check_principal_logarithm(const Mat4& a) {
  if (!all_finite(a)) return error(MatrixErrorCode::NotFinite, "the matrix has nan or inf entries");
  const Eigen::EigenSolver<Mat4> es(a, false);
  if (es.info() != Eigen::Success) return error(MatrixErrorCode::NoConvergence, "eigenvalue computation failed");
  const double scale = std::max(norm_inf(a), 1e-300);
  for (int i = 0; i < 4; ++i) {
    const std::complex<double> l = es.eigenvalues()[i];
    const double mag = std::abs(l);
    if (mag <= 1e-14 * scale)
      return error(MatrixErrorCode::NoPrincipalLogarithm, "the matrix is singular (eigenvalue %.3g): no logarithm", mag);
    if (l.real() < 0.0 && std::abs(l.imag()) <= 1e-9 * mag)
      return error(MatrixErrorCode::NoPrincipalLogarithm,
                   "negative real eigenvalue %.6g: no real principal logarithm or square root "
                   "(a rotation of pi/2 or more with non-uniform scale, or a reflection)",
                   l.real());
  }
  return std::monostate{};
}

MatrixResult matrix_sqrt(const Mat4& a, const SqrtOptions& o, SqrtTrace* trace) {
  if (auto c = check_principal_logarithm(a); c.index() == 1) {
    MatrixError e = std::get<1>(std::move(c));
    e.message = "square root: " + e.message;
    return e;
  }
  return sqrt_iteration(a, o, trace);
}

MatrixResult matrix_log(const Mat4& a_in, const LogOptions& o, LogTrace* trace) {
  if (auto c = check_principal_logarithm(a_in); c.index() == 1) {
    MatrixError e = std::get<1>(std::move(c));
    e.message = "logarithm: " + e.message;
    return e;
  }
  const Mat4 id = Mat4::Identity();
  Mat4 a = a_in;
  int k = 0;
  int sqrt_iterations = 0;
  const bool fixed = o.fixed_square_roots >= 0;
  while (fixed ? k < o.fixed_square_roots : norm_inf(a - id) > o.epsilon1) {
    if (!fixed && k == o.max_square_roots)
      return error(MatrixErrorCode::NoConvergence,
                   "logarithm: %g square roots did not bring |A - I| = %.3g below eps1 = %.3g", k, norm_inf(a - id),
                   o.epsilon1);
    // Traced only when asked: the trace's residual list allocates (the daemon's lerp must not).
    SqrtTrace st;
    MatrixResult r = sqrt_iteration(a, o.sqrt, trace ? &st : nullptr);
    sqrt_iterations += st.iterations;
    if (!r) {
      MatrixError e = r.error();
      e.message = "logarithm: " + e.message;
      return e;
    }
    a = r.value();
    ++k;
  }
  const Mat4 b = a - id;
  Mat4 z = b, x = b;
  int terms = 0;
  for (int i = 2; norm_inf(z) > o.epsilon2; ++i) {
    if (terms == o.max_series_terms)
      return error(MatrixErrorCode::NoConvergence, "logarithm: the series did not reach eps2 = %.3g in %g terms (|B| = %.3g)",
                   o.epsilon2, terms, norm_inf(b));
    z = -(z * b);
    x += z / static_cast<double>(i);
    ++terms;
  }
  if (trace) {
    trace->square_roots = k;
    trace->sqrt_iterations = sqrt_iterations;
    trace->series_terms = terms;
    trace->distance_to_identity = norm_inf(b);
  }
  x *= std::ldexp(1.0, k);
  if (!all_finite(x)) return error(MatrixErrorCode::NotFinite, "logarithm: the result is not finite");
  return x;
}

}  // namespace posefair
