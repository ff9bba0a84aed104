#pragma once
// Weights that turn keyframes into frames, for eq. 8 (e^{sum w_i log M_i}): the three methods
// of Hawkins & Grimm Section 3.
//   linear:        per segment (1-u, u) on keys i, i+1 (eq. 3), the origin being key i (eq. 7);
//   approximating: cubic B-spline basis (C^2) on a clamped, non-uniform knot vector averaged
//                  from the key times (degree min(3, n-1));
//   subdivision:   the 4-point scheme (eqs. 9-12) with the boundary dummies of ERRATA item 1
//                  (M_-1 = e^{2 log M_0 - log M_1}, i.e. weights 2, -1 in log space), unrolled
//                  into weight lists over the keys and resampled in one pass (eqs. 15-16).
// The origin of every frame but the linear ones is the key with the largest weight (3.3.1).
#include <span>
#include <vector>

namespace posefair {

struct WeightTerm {
  int key;
  double weight;
};

struct FrameWeights {
  std::vector<WeightTerm> terms;  // keys with non-zero weight, in increasing key order
  int origin = 0;                 // the key whose transform the frame is combined about
};

enum class InterpolationMethod { Linear, Approximating, Subdivision };

// Clamped knot vector for n = key_times.size() control points of the given degree: degree+1
// copies of the first and last time, interior knots averaged over `degree` consecutive times.
std::vector<double> bspline_knots(std::span<const double> key_times, int degree);
// The B-spline basis values N_{i,degree}(t) for all n control points (sum 1, non-negative).
std::vector<double> bspline_basis(std::span<const double> knots, int n, int degree, double t);

// Dense weights over n keys of the (n-1)2^levels + 1 points after `levels` rounds of the
// 4-point scheme; row r is point r. Keys are rows r = i 2^levels.
std::vector<std::vector<double>> subdivision_weights(int n, int levels);
// The paper's rule: the fewest rounds m with (n-1)2^m + 1 > frames (at least 0, at most 16).
int subdivision_levels(int n, int frames);

// Weights of each frame time for n = key_times.size() keys at strictly increasing times;
// frame times outside the keys' span are clamped to it.
std::vector<FrameWeights> frame_weights(InterpolationMethod method, std::span<const double> key_times,
                                        std::span<const double> frame_times);

}  // namespace posefair
