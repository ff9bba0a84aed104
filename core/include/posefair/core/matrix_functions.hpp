#pragma once
// Matrix exponential, square root and logarithm of 4x4 transforms by the iterations in
// Hawkins & Grimm, Section 4 (after Alexa 2002), with the paper's termination constants.
// Every function returns a MatrixResult: either the matrix or a typed error saying why there
// is none (no principal real logarithm, no convergence, non-finite data). A wrong matrix is
// never returned silently. All norms are the infinity norm (max row sum, ERRATA item 2).
// Fixed-size 4x4 only: nothing here allocates on the success path.
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Core>

namespace posefair {

using Mat4 = Eigen::Matrix4d;

enum class MatrixErrorCode {
  NoPrincipalLogarithm,  // an eigenvalue on the closed negative real axis (ERRATA item 4)
  NoConvergence,         // an iteration hit its cap before reaching its epsilon
  NotFinite,             // nan/inf in the input, or overflow in the result
  UnsafeStep,            // a keyframe step rotates by pi/2 or more (Section 3.2)
};

struct MatrixError {
  MatrixErrorCode code;
  std::string message;
  int key = -1;         // keyframe interpolation: the keyframe that failed (-1: none)
  int origin_key = -1;  // ... and the keyframe it was taken relative to
};

const char* to_string(MatrixErrorCode c);

// A matrix or the reason there is none. (C++20 has no std::expected.)
template <class T>
class Result {
 public:
  Result(T value) : v_(std::move(value)) {}                 // NOLINT: implicit by design
  Result(MatrixError error) : v_(std::move(error)) {}       // NOLINT
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  const T& value() const { return std::get<0>(v_); }
  T& value() { return std::get<0>(v_); }
  const T& operator*() const { return value(); }
  const MatrixError& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, MatrixError> v_;
};
using MatrixResult = Result<Mat4>;

// Infinity norm: the largest absolute row sum.
double norm_inf(const Mat4& a);

// Figure 2: Pade approximant of degree q with scaling by 2^-j, j = max(0, 1 + floor(log2 |A|)),
// then j squarings.
struct ExpOptions {
  int pade_degree = 6;  // q; MATLAB's value, as in the paper
};
MatrixResult matrix_exp(const Mat4& a, const ExpOptions& o = {});

// Figure 3(b): Denman-Beavers iteration X <- (X + Y^-1)/2, Y <- (Y + X^-1)/2 from X = A, Y = I,
// until |XX - A| < eps3, at most max_iterations updates.
struct SqrtOptions {
  double epsilon = 1e-6;  // eps3
  int max_iterations = 10;
  bool relative = false;  // compare |XX - A| with epsilon |A| instead of epsilon (not in the paper)
};
// What the iteration did, for the Section 4.2 studies.
struct SqrtTrace {
  int iterations = 0;
  std::vector<double> residuals;  // |XX - A| before each update and after the last
};
MatrixResult matrix_sqrt(const Mat4& a, const SqrtOptions& o = {}, SqrtTrace* trace = nullptr);
// The bare iteration without the eigenvalue check (for the studies of matrices that have no
// principal square root; it then fails to converge or diverges).
MatrixResult denman_beavers_sqrt(const Mat4& a, const SqrtOptions& o = {}, SqrtTrace* trace = nullptr);

// Figure 3(a): k square roots until |A - I| < eps1 (at most max_square_roots), then the series
// log(I + B) = B - B^2/2 + B^3/3 - ... until a term's |B^i| < eps2 (at most max_series_terms),
// times 2^k.
struct LogOptions {
  double epsilon1 = 1e-4;
  int max_square_roots = 20;
  double epsilon2 = 1e-9;
  int max_series_terms = 7;
  SqrtOptions sqrt;
  // Studies only: take exactly this many square roots and ignore epsilon1 (-1: off).
  int fixed_square_roots = -1;

  // The defaults are the paper's constants. They leave a relative error of about
  // (square-root residual) / eps1 + eps2 / eps1, i.e. 1e-4 (docs/matrix-interpolation.md).
  // This preset reaches ~1e-10 for a few more iterations: eps3 = 1e-13 relative, eps1 = 1e-3,
  // eps2 = 1e-17, caps 40 roots / 12 terms.
  static LogOptions precise() {
    LogOptions o;
    o.epsilon1 = 1e-3;
    o.max_square_roots = 40;
    o.epsilon2 = 1e-17;
    o.max_series_terms = 12;
    o.sqrt.epsilon = 1e-13;
    o.sqrt.relative = true;
    return o;
  }
};
struct LogTrace {
  int square_roots = 0;
  int sqrt_iterations = 0;         // summed over the square roots
  int series_terms = 0;            // terms added after the first
  double distance_to_identity = 0; // |A^(1/2^k) - I| when the series started
};
MatrixResult matrix_log(const Mat4& a, const LogOptions& o = {}, LogTrace* trace = nullptr);

// The no-real-logarithm test: does A have an eigenvalue on the closed negative real axis
// (including 0)? |Im l| <= 1e-9 |l| counts as real. Returns the offending eigenvalue's
// description in the error, or nothing when A is fine.
std::variant<std::monostate, MatrixError> check_principal_logarithm(const Mat4& a);

}  // namespace posefair
