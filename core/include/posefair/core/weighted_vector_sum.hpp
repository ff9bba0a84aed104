#pragma once
// Σ_j w(j)·v_j over j in [first, end) of 3-vectors, in four partial sums. The engine's rows and
// its motion fit are such sums over up to a whole window (128 terms at 1 kHz); with one running
// sum every add waits for the one before (a 4-cycle latency per term), with four independent
// sums the adds overlap. The additions are grouped differently from a plain loop, so the
// result may differ from one in the last bits.
// Two neighbouring 3-vectors are six contiguous doubles: three 2-wide vector operations (GCC's
// and Clang's vector extensions, which the build's compilers are), where each 3-vector alone
// takes a 2-wide and a scalar one and the compiler builds the weights' pairs through memory.
#include <cstring>
#include <span>

#include "posefair/core/so3.hpp"

namespace posefair {

template <class Weight>
Vec3 weighted_vector_sum(int first, int end, Weight&& w, std::span<const Vec3> v) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "a span of Vec3 is contiguous doubles");
  using Two = double __attribute__((vector_size(16)));
  auto load = [](const double* p) {
    Two t;
    std::memcpy(&t, p, sizeof t);
    return t;
  };
  // The partial sums s0 … s3 of terms j ≡ 0 … 3 (mod 4): a holds s0 and s1 as
  // (s0x s0y)(s0z s1x)(s1y s1z), b likewise s2 and s3.
  Two a0{}, a1{}, a2{}, b0{}, b1{}, b2{};
  int j = first;
  for (; j + 4 <= end; j += 4) {
    const double* p = v[static_cast<std::size_t>(j)].data();
    const double w0 = w(j), w1 = w(j + 1), w2 = w(j + 2), w3 = w(j + 3);
    a0 += Two{w0, w0} * load(p);
    a1 += Two{w0, w1} * load(p + 2);
    a2 += Two{w1, w1} * load(p + 4);
    b0 += Two{w2, w2} * load(p + 6);
    b1 += Two{w2, w3} * load(p + 8);
    b2 += Two{w3, w3} * load(p + 10);
  }
  Vec3 s0(a0[0], a0[1], a1[0]);
  for (; j < end; ++j) s0 += w(j) * v[static_cast<std::size_t>(j)];
  return (s0 + Vec3(a1[1], a2[0], a2[1])) + (Vec3(b0[0], b0[1], b1[0]) + Vec3(b1[1], b2[0], b2[1]));
}

}  // namespace posefair
