#pragma once
// Unit-quaternion exp, log and products on several quaternions at once, without branches or
// library calls, for loops over structure-of-arrays data (the batch fairing sweep).
//
// T is either double (one quaternion) or Lane (kLaneWidth quaternions side by side, in Eigen's
// SIMD packets). The same template code serves both, so a loop runs its body on Lanes and the
// remainder on doubles with the same arithmetic.
//
// Same convention as so3.hpp: exp(v) = (cos|v|, v̂ sin|v|), log its inverse on w ≥ 0. Instead of
// sin, cos and atan2 (scalar library calls, the bulk of the cost) these use polynomials:
//   exp: cos θ and sin θ / θ as Taylor polynomials in θ² (no square root, exact at θ = 0); the
//        truncation error is below 1e-17 for |v| ≤ π/2, which is every argument of the sweep.
//   log: θ = atan2(|v|, w) through t = tan(θ/8) ≤ tan(π/16) (half-angle steps), then
//        atan(t)/t as a Taylor polynomial in t² (error below 1e-18); the scale θ/|v| is formed
//        without dividing by |v|, so it is exact at v = 0 too. Two square roots, two divisions.
// Both agree with so3::exp and so3::log to a few units in the last place (tested).
#include <array>
#include <cmath>
#include <cstddef>

#include <Eigen/Core>

// Everything here is small and called in one loop body: inline it all, or the lanes travel
// through memory between calls (GCC's size heuristics otherwise leave log and the polynomials out).
#define POSEFAIR_LANE_INLINE [[gnu::always_inline]] inline

namespace posefair::lanes {

// A Lane is a few SIMD registers of doubles, worked on with Eigen's packet primitives (Packet2d
// with SSE2, Packet4d with AVX). Eigen's Array<double, N, 1> would express the same, but GCC
// stops inlining its evaluators in a loop body this size and the lanes then travel through
// memory (measured: 2.4 ms against 1.2 for the paper's case); the packets stay in registers.
using Packet = Eigen::internal::packet_traits<double>::type;
// Packets per lane: independent chains of arithmetic, so the latency of one (the polynomials,
// the square roots and divisions of log) overlaps with the others'.
inline constexpr int kPacketsPerLane = 4;  // measured: 1 → 2.1 ms, 2 → 1.5, 4 → 1.2, 8 → 1.2 (paper's case)
inline constexpr int kLaneWidth = kPacketsPerLane * Eigen::internal::packet_traits<double>::size;

struct Lane {
  Packet v[kPacketsPerLane];
};
template <class F> POSEFAIR_LANE_INLINE Lane lanewise(F f, const Lane& a, const Lane& b) {
  Lane r;
  for (int k = 0; k < kPacketsPerLane; ++k) r.v[k] = f(a.v[k], b.v[k]);
  return r;
}
POSEFAIR_LANE_INLINE Lane broadcast(double v) {
  Lane r;
  for (int k = 0; k < kPacketsPerLane; ++k) r.v[k] = Eigen::internal::pset1<Packet>(v);
  return r;
}
POSEFAIR_LANE_INLINE Lane operator+(const Lane& a, const Lane& b) {
  return lanewise([](const Packet& x, const Packet& y) { return Eigen::internal::padd(x, y); }, a, b);
}
POSEFAIR_LANE_INLINE Lane operator-(const Lane& a, const Lane& b) {
  return lanewise([](const Packet& x, const Packet& y) { return Eigen::internal::psub(x, y); }, a, b);
}
POSEFAIR_LANE_INLINE Lane operator*(const Lane& a, const Lane& b) {
  return lanewise([](const Packet& x, const Packet& y) { return Eigen::internal::pmul(x, y); }, a, b);
}
POSEFAIR_LANE_INLINE Lane operator/(const Lane& a, const Lane& b) {
  return lanewise([](const Packet& x, const Packet& y) { return Eigen::internal::pdiv(x, y); }, a, b);
}
POSEFAIR_LANE_INLINE Lane operator-(const Lane& a) { return broadcast(0.0) - a; }
POSEFAIR_LANE_INLINE Lane operator+(const Lane& a, double b) { return a + broadcast(b); }
POSEFAIR_LANE_INLINE Lane operator-(const Lane& a, double b) { return a - broadcast(b); }
POSEFAIR_LANE_INLINE Lane operator*(const Lane& a, double b) { return a * broadcast(b); }
POSEFAIR_LANE_INLINE Lane operator/(const Lane& a, double b) { return a / broadcast(b); }
POSEFAIR_LANE_INLINE Lane operator+(double a, const Lane& b) { return broadcast(a) + b; }
POSEFAIR_LANE_INLINE Lane operator-(double a, const Lane& b) { return broadcast(a) - b; }
POSEFAIR_LANE_INLINE Lane operator*(double a, const Lane& b) { return broadcast(a) * b; }

// --- the operations that differ between double and Lane ---------------------------------
template <class T> T splat(double v);
template <> POSEFAIR_LANE_INLINE double splat<double>(double v) { return v; }
template <> POSEFAIR_LANE_INLINE Lane splat<Lane>(double v) { return broadcast(v); }

template <class T> T load(const double* p);
template <> POSEFAIR_LANE_INLINE double load<double>(const double* p) { return *p; }
template <> POSEFAIR_LANE_INLINE Lane load<Lane>(const double* p) {
  Lane r;
  for (int k = 0; k < kPacketsPerLane; ++k) r.v[k] = Eigen::internal::ploadu<Packet>(p + k * (kLaneWidth / kPacketsPerLane));
  return r;
}

POSEFAIR_LANE_INLINE void store(double* p, double v) { *p = v; }
POSEFAIR_LANE_INLINE void store(double* p, const Lane& v) {
  for (int k = 0; k < kPacketsPerLane; ++k) Eigen::internal::pstoreu(p + k * (kLaneWidth / kPacketsPerLane), v.v[k]);
}

POSEFAIR_LANE_INLINE double lane_sqrt(double x) { return std::sqrt(x); }
POSEFAIR_LANE_INLINE Lane lane_sqrt(const Lane& x) {
  Lane r;
  for (int k = 0; k < kPacketsPerLane; ++k) r.v[k] = Eigen::internal::psqrt(x.v[k]);
  return r;
}

// a < b ? yes : no, lane by lane.
POSEFAIR_LANE_INLINE double if_less(double a, double b, double yes, double no) { return a < b ? yes : no; }
POSEFAIR_LANE_INLINE Lane if_less(const Lane& a, const Lane& b, const Lane& yes, const Lane& no) {
  Lane r;
  for (int k = 0; k < kPacketsPerLane; ++k)
    r.v[k] = Eigen::internal::pselect(Eigen::internal::pcmp_lt(a.v[k], b.v[k]), yes.v[k], no.v[k]);
  return r;
}

POSEFAIR_LANE_INLINE double lane_max(double a, double b) { return a < b ? b : a; }
POSEFAIR_LANE_INLINE Lane lane_max(const Lane& a, const Lane& b) { return if_less(a, b, b, a); }
POSEFAIR_LANE_INLINE double max_of(double a) { return a; }
POSEFAIR_LANE_INLINE double max_of(const Lane& a) {
  double m = Eigen::internal::predux_max(a.v[0]);
  for (int k = 1; k < kPacketsPerLane; ++k) m = lane_max(m, Eigen::internal::predux_max(a.v[k]));
  return m;
}

// --- quaternions and vectors of T ----------------------------------------------------------
template <class T> struct QuatOf { T w, x, y, z; };
template <class T> struct VecOf { T x, y, z; };

// Hamilton product a b.
template <class T> POSEFAIR_LANE_INLINE QuatOf<T> multiply(const QuatOf<T>& a, const QuatOf<T>& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

// a⁻¹ b for unit a (the conjugate times b).
template <class T> POSEFAIR_LANE_INLINE QuatOf<T> conjugate_times(const QuatOf<T>& a, const QuatOf<T>& b) {
  return {a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z, a.w * b.x - a.x * b.w - a.y * b.z + a.z * b.y,
          a.w * b.y + a.x * b.z - a.y * b.w - a.z * b.x, a.w * b.z - a.x * b.y + a.y * b.x - a.z * b.w};
}

template <class T> POSEFAIR_LANE_INLINE T dot(const QuatOf<T>& a, const QuatOf<T>& b) { return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z; }

template <class T> POSEFAIR_LANE_INLINE QuatOf<T> normalized(const QuatOf<T>& q) {
  const T inv = splat<T>(1.0) / lane_sqrt(dot(q, q));
  return {q.w * inv, q.x * inv, q.y * inv, q.z * inv};
}

// --- exp and log -----------------------------------------------------------------------------
namespace detail {
// Taylor coefficients in z = θ²: cos θ = Σ (−1)^k z^k/(2k)!, sin θ/θ = Σ (−1)^k z^k/(2k+1)!, and
// atan(t)/t = Σ (−1)^k z^k/(2k+1) with z = t². Thirteen terms each (k = 0 … 12).
inline constexpr int kTerms = 13;
constexpr std::array<double, kTerms> cos_coefficients() {
  std::array<double, kTerms> c{};
  double f = 1.0;
  for (int k = 0; k < kTerms; ++k) {
    if (k > 0) f *= static_cast<double>((2 * k - 1) * (2 * k));
    c[k] = (k % 2 ? -1.0 : 1.0) / f;
  }
  return c;
}
constexpr std::array<double, kTerms> sinc_coefficients() {
  std::array<double, kTerms> c{};
  double f = 1.0;
  for (int k = 0; k < kTerms; ++k) {
    if (k > 0) f *= static_cast<double>((2 * k) * (2 * k + 1));
    c[k] = (k % 2 ? -1.0 : 1.0) / f;
  }
  return c;
}
constexpr std::array<double, kTerms> atanc_coefficients() {
  std::array<double, kTerms> c{};
  for (int k = 0; k < kTerms; ++k) c[k] = (k % 2 ? -1.0 : 1.0) / static_cast<double>(2 * k + 1);
  return c;
}
inline constexpr std::array<double, kTerms> kCos = cos_coefficients();
inline constexpr std::array<double, kTerms> kSinc = sinc_coefficients();
inline constexpr std::array<double, kTerms> kAtanc = atanc_coefficients();

template <class T> POSEFAIR_LANE_INLINE T horner(const std::array<double, kTerms>& c, const T& z) {
  T r = z * c[kTerms - 1] + c[kTerms - 2];
  for (int k = kTerms - 3; k >= 0; --k) r = r * z + c[k];
  return r;
}
}  // namespace detail

// exp(v) for |v| ≤ π/2 (accurate to rounding up to |v| ≈ 2).
template <class T> POSEFAIR_LANE_INLINE QuatOf<T> exp(const VecOf<T>& v) {
  const T z = v.x * v.x + v.y * v.y + v.z * v.z;
  const T s = detail::horner(detail::kSinc, z);
  return {detail::horner(detail::kCos, z), s * v.x, s * v.y, s * v.z};
}

// log(q) on the hemisphere w ≥ 0, for unit q (|q| − 1 of rounding size changes the result by
// as much, relatively); |log q| ≤ π/2.
template <class T> POSEFAIR_LANE_INLINE VecOf<T> log(const QuatOf<T>& q) {
  const T one = splat<T>(1.0);
  const T sign = if_less(q.w, splat<T>(0.0), splat<T>(-1.0), one);
  const T s2 = q.x * q.x + q.y * q.y + q.z * q.z;  // sin²θ
  // With c = 1 + |w| = 2cos²(θ/2): tan(θ/4) = sin(θ/2)/(1 + cos(θ/2)) = s/(√(2c) + c), and
  // tan(θ/8) = t/(1 + √(1 + t²)) with t = tan(θ/4). Only squares and reciprocals are formed.
  const T c = one + sign * q.w;
  const T r4 = one / (lane_sqrt(T(c + c)) + c);  // tan(θ/4)/s
  const T d8 = one + lane_sqrt(T(one + s2 * r4 * r4));
  const T r8 = r4 / d8;  // tan(θ/8)/s
  // θ/s = 8 atan(t8)/s = 8 (atan(t8)/t8) (t8/s).
  const T scale = sign * splat<T>(8.0) * detail::horner(detail::kAtanc, T(s2 * r8 * r8)) * r8;
  return {scale * q.x, scale * q.y, scale * q.z};
}

}  // namespace posefair::lanes
