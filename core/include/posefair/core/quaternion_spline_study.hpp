#pragma once
// Ramamoorthi & Barr's Section 4 claims on one key set, as data for docs/quaternion-splines.md:
// how far the 4-variable-frame curve is from the optimum ("within 0.1 %"), and how its
// deviation from unit norm is spread ("maximum frequently less than 1 %, with the average
// deviation about one tenth of that").
#include "posefair/core/quaternion_spline.hpp"

namespace posefair {

struct KeySetClaims {
  double optimum = 0.0;    // estimate: all 24 segment-start frames, every piece split once more (54 frames)
  double objective_4 = 0.0, objective_8 = 0.0, objective_24 = 0.0;  // 4, 8 frames (one per round), 24
  double gap_4 = 0.0, gap_8 = 0.0, gap_24 = 0.0;  // (objective − optimum) / optimum
  double max_norm_deviation_4 = 0.0;   // max over the 4-frame curve of | |q| − 1 |
  double mean_norm_deviation_4 = 0.0;  // its average over time
};

// The paper's settings: α = 1000, 5 segments per interval, one frame per refinement round.
KeySetClaims key_set_claims(const SplineKeyframes& keys);

// The time average of | |q(t)| − 1 | over the curve, by `samples` equally spaced times.
double mean_norm_deviation(const HermiteCurve4& curve, int samples = 6001);

}  // namespace posefair
