#pragma once
// Alexa's linear combination of transformations as used by Hawkins & Grimm:
//   s (.) A = e^{s log A}            (eq. 1)
//   A (+) B = e^{log A + log B}      (eq. 2)
//   lerp = [(1-t) (.) A] (+) [t (.) B]  (eq. 3), evaluated about an "origin" X (eq. 7):
//   lerp_X(A, B, t) = e^{(1-t) log(A X^-1) + t log(B X^-1)} X,
// and the weighted combination e^{sum w_i log(M_i X^-1)} X (eq. 8).
// Taking X = A (or, for cameras, A's view matrix) keeps the logarithms near the identity, where
// the iterations are safe; a step whose rotational part is pi/2 or more is refused with a
// message asking for another keyframe (Section 3.2).
#include <span>

#include "posefair/core/matrix_functions.hpp"

namespace posefair {

// Rotation angle (radians, [0, pi]) of the orthogonal polar factor of the upper-left 3x3 of m:
// the "rotational component" of an affine transform with scale or shear.
double rotational_component(const Mat4& m);

struct CombinationOptions {
  LogOptions log;  // the paper's constants; LogOptions::precise() for ~1e-10
  ExpOptions exp;
  double max_step_angle = 1.5707963267948966;  // pi/2: steps at or above it are refused
  static CombinationOptions precise() {
    CombinationOptions o;
    o.log = LogOptions::precise();
    return o;
  }
};

MatrixResult scale(double s, const Mat4& a, const CombinationOptions& o = {});    // s (.) A
MatrixResult add(const Mat4& a, const Mat4& b, const CombinationOptions& o = {});  // A (+) B

// Eq. 3 as printed (no change of origin).
MatrixResult lerp_direct(const Mat4& a, const Mat4& b, double t, const CombinationOptions& o = {});
// Eq. 7 with origin X = a: e^{t log(B A^-1)} A.
MatrixResult lerp(const Mat4& a, const Mat4& b, double t, const CombinationOptions& o = {});

// Two keyframes prepared once (two logarithms, or one when the origin is a itself), then any
// number of evaluations at one exponential and a 4x4 product each. For a daemon resampling a
// pose stream between two samples: build once per sample pair, call at(t) per output.
class PreparedLerp {
 public:
  // About the origin x (eq. 7); refuses a step whose rotational part after the change of
  // origin is max_step_angle or more (UnsafeStep).
  static Result<PreparedLerp> make(const Mat4& a, const Mat4& b, const Mat4& x, const CombinationOptions& o = {});
  // About a itself.
  static Result<PreparedLerp> make(const Mat4& a, const Mat4& b, const CombinationOptions& o = {}) {
    return make(a, b, a, o);
  }
  MatrixResult at(double t) const;

 private:
  PreparedLerp(const Mat4& log_a, const Mat4& log_b, const Mat4& x, const ExpOptions& e)
      : log_a_(log_a), log_b_(log_b), origin_(x), exp_(e) {}
  Mat4 log_a_, log_b_, origin_;
  ExpOptions exp_;
};

// log(m x^-1), refusing (UnsafeStep) when m x^-1 rotates by max_step_angle or more.
MatrixResult log_about(const Mat4& m, const Mat4& x, const CombinationOptions& o);

// Eq. 8 about the origin x: e^{sum w_i log(M_i x^-1)} x. weights and matrices have equal length.
MatrixResult combine(std::span<const double> weights, std::span<const Mat4> matrices, const Mat4& x,
                     const CombinationOptions& o = {});

}  // namespace posefair
