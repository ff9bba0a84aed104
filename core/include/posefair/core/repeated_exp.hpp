#pragma once
// e^x for an argument that nearly always repeats: a stream's time step (e^(−dt/τ), a factor per
// sample) is the same from sample to sample but for the rounding of its time stamps. Kept for
// the last argument and reused within 10⁻⁹ of it (relative), where the value differs from the exact
// one by 10⁻⁹·|x| relative: below 10⁻¹¹ for the engine's factors per sample. The exponentials per
// sample were among the engine's costs (docs/engine.md, "Cost").
#include <cmath>

namespace posefair {

class RepeatedExp {
 public:
  double operator()(double x) {
    if (!(std::abs(x - x_) <= 1e-9 * std::abs(x))) {
      x_ = x;
      value_ = std::exp(x);
    }
    return value_;
  }

 private:
  double x_ = NAN;  // (compares with nothing: the first call computes)
  double value_ = 1.0;
};

}  // namespace posefair
