#pragma once
// Σ_j w(j)·v_j over j in [first, end) of 3-vectors, in four partial sums. The engine's rows and
// its motion fit are such sums over up to a whole window (128 terms at 1 kHz); with one running
// sum every add waits for the one before (a 4-cycle latency per term), with four independent
// sums the adds overlap. The additions are grouped differently from a plain loop, so the
// result may differ from one in the last bits.
#include <span>

#include "posefair/core/so3.hpp"

namespace posefair {

template <class Weight>
Vec3 weighted_vector_sum(int first, int end, Weight&& w, std::span<const Vec3> v) {
  Vec3 s0 = Vec3::Zero(), s1 = Vec3::Zero(), s2 = Vec3::Zero(), s3 = Vec3::Zero();
  int j = first;
  for (; j + 4 <= end; j += 4) {
    const auto i = static_cast<std::size_t>(j);
    s0 += w(j) * v[i];
    s1 += w(j + 1) * v[i + 1];
    s2 += w(j + 2) * v[i + 2];
    s3 += w(j + 3) * v[i + 3];
  }
  for (; j < end; ++j) s0 += w(j) * v[static_cast<std::size_t>(j)];
  return (s0 + s1) + (s2 + s3);
}

}  // namespace posefair
