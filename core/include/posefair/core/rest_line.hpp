#pragma once
// A still stream averaged over seconds (the engine's default at rest, docs/engine.md "At rest").
//
// At rest the window's heaviest smoothing is a line through its half second, extrapolated to
// the newest sample: it keeps about 2/√W of the noise (0.28σ at 100 Hz). A tracker put down or
// a head held still can be averaged for longer. This is the least-squares line through every
// sample since the stream came to rest, each weighing e^(−age/memory): with a memory of 1 s its
// newest value keeps 0.11σ at 100 Hz. A slow motion the rest test cannot see (a sway, a drift
// that speeds up) bends the samples, and a line with a long memory lags behind it; a quadratic
// through the same samples with the same weights follows the bend. So the line is taken only
// while the two agree within a few times the noise their difference carries, which the
// weights give exactly (the sums below, with the weights squared). Where the line is flat
// within its noise, the weighted mean of the same samples (the level) keeps less of it, and the
// line's value is moved toward it as far as the two's difference allows.
// Sums of fixed size, updated per sample in O(1); no allocation.
#include <array>
#include <optional>

#include "posefair/core/repeated_exp.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

// The line is taken while the difference's mean square per component is under this many times
// its noise: noise alone puts it over 3 times in 100 (a χ² with 3 degrees of freedom over 9).
// At 2, still streams kept less of the gain (18% instead of 23% less error at 100 Hz); at 4 a
// slow sway at 30 Hz (0.5 Hz, 0.01 rad under noise of 0.01) lost 1.6% instead of 0.2%.
inline constexpr double kRestLineFactor = 3.0;
// The line's value is moved toward the level, the weighted mean of the same samples, which keeps
// less noise (0.071σ against the line's 0.11σ at 100 Hz with a memory of 1 s) but lags a drift
// (by v·memory). How far: by the weight with the least expected square error, the bias in it
// taken as this many times the level-minus-line difference's mean square (noise included). At 1
// (the difference's square as it stands) still streams gained 12% instead of 9% but slow drifts
// under the noise lost up to 2.1% instead of 0.8%. At 0 (the level wherever the line is taken)
// a drift of 0.005 rad/s under noise of 0.006 had 2.5 times the error at 250 Hz; the level taken
// while it and the line agree within 3 times their difference's noise, drifts of 0.002 rad/s
// lost up to 6.5%.
inline constexpr double kLevelBiasFactor = 2.0;
// A sample that lands off the line's prediction by a mean square per component over this many
// times the noise is off the still pose (FairingWindow keeps it out of the line, and emits the
// second of two in a row as measured): Gaussian noise puts it there once in 14 million samples
// (a χ² with 3 degrees of freedom over 36). At 8, heavy-tailed noise (Student's t, 4 degrees of
// freedom) at 1 kHz nearly tripled a still stream's jitter.
inline constexpr double kRestDepartureFactor = 12.0;
// The weight a judgement of what a first sample off the line was keeps per later judgement
// (FairingWindow::Channel::Departures): about the last ten count.
inline constexpr double kDepartureMemory = 0.9;
// How much further off than the furthest that began a motion a first sample off the line may be
// and still be taken for one.
inline constexpr double kDepartureReach = 4.0;

class RestLine {
 public:
  void reset();
  bool empty() const { return weights_[0] == 0.0; }
  // A sample y (one channel's coordinate from the rest's first sample) taken dt
  // seconds after the last one, weighing `weight` (its noise variance 1/weight times the
  // others': a sample taken in a burst of noise, FairingWindow).
  void add(double dt, const Vec3& y, double memory_s, double weight = 1.0);
  // The still pose `age` seconds before the newest sample (negative: after it, a prediction):
  // the line's value moved toward the level (kLevelBiasFactor), and whether the line is
  // straight: whether the quadratic's value there differs from the line's by less than `factor`
  // times the noise their difference carries (noise_var: the measurements', per component) in
  // mean square per component. None while three distinct times are not yet in.
  struct Value {
    Vec3 pose;
    bool straight = false;
  };
  std::optional<Value> value_at(double age, double noise_var, double factor) const;
  // The line's value alone, at a fraction of the cost (none while value_at has none for want of
  // three distinct times).
  std::optional<Vec3> line_at(double age) const;

 private:
  // The line's weights on Σw·y and Σw·a·y for its value at `age` (both of the above take it).
  std::optional<std::array<double, 2>> line_weights(double age) const;
  std::array<double, 5> weights_{};  // Σ w·a^k, k = 0..4 (a: age in seconds)
  std::array<double, 5> squares_{};  // Σ w²·a^k: the noise the fits' weights carry
  std::array<Vec3, 3> values_{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // Σ w·a^k·y, k = 0..2
  int steps_ = 0;  // steps of positive length taken, up to 2
  RepeatedExp decay_;  // e^(−dt/memory) per step
};

}  // namespace posefair
