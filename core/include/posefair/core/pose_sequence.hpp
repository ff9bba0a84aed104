#pragma once
// The sequence every batch algorithm and every pose file reader shares: sample times,
// unit quaternions, and optional positions (empty when the stream is orientation-only).
#include <cstddef>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair {

struct PoseSequence {
  std::vector<double> time;      // seconds, non-decreasing
  std::vector<Quat> orientation; // unit quaternions
  std::vector<Vec3> position;    // empty, or one per sample

  std::size_t size() const { return orientation.size(); }
  bool has_position() const { return !position.empty(); }
};

}  // namespace posefair
