#pragma once
// A tracker that rests and turns (a head in VR, a tool put down and picked up): still for a
// while, then turned about a random axis by a random angle in a short time (smoothstep in the
// angle, so the turn starts and stops with no jump in speed), still again, and so on. The
// benchmarks' generated motions (the quality benchmark's rests set, bench streams' quick turns).
// Deterministic for a given generator state.
#include <random>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair {

struct RestsAndTurnsSpec {
  double seconds = 20.0;                                // turns start before this
  double rest_min_s = 1.0, rest_max_s = 3.0;            // still for this long before each turn
  double angle_min_deg = 20.0, angle_max_deg = 90.0;    // each turn's angle
  double turn_min_s = 0.3, turn_max_s = 0.8;            // each turn's duration
};

class RestsAndTurns {
 public:
  // Draws the turns from rng (uniform within each range, the axis uniform on the sphere).
  RestsAndTurns(const RestsAndTurnsSpec& spec, std::mt19937_64& rng);
  // The orientation at time t (s); identity before the first turn.
  Quat at(double t) const;

 private:
  struct Turn {
    double start, duration;
    Vec3 rotation;  // axis × angle (rad)
    Quat before;
  };
  std::vector<Turn> turns_;
};

}  // namespace posefair
