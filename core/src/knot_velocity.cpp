#include "posefair/core/knot_velocity.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace posefair::geometric_splines {

std::string_view to_string(KnotVelocityEstimator e) {
  switch (e) {
    case KnotVelocityEstimator::CentralDifference: return "central";
    case KnotVelocityEstimator::Bessel: return "bessel";
    case KnotVelocityEstimator::LocalQuadraticFit: return "fit";
  }
  return "?";
}

void validate(const KnotVelocityOptions& options) {
  if (options.fit_half_width < 1 || options.fit_half_width > kMaxFitHalfWidth)
    throw std::invalid_argument("fit half width must be in 1.." + std::to_string(kMaxFitHalfWidth) + ", got " +
                                std::to_string(options.fit_half_width));
}

std::pair<std::size_t, std::size_t> knot_velocity_neighbourhood(const KnotVelocityOptions& options, std::size_t i,
                                                                std::size_t count) {
  const std::size_t last_index = count == std::numeric_limits<std::size_t>::max() ? count : count - 1;
  switch (options.estimator) {
    case KnotVelocityEstimator::CentralDifference:
      return {i == 0 ? 0 : i - 1, std::min(i + 1, last_index)};
    case KnotVelocityEstimator::Bessel:
    case KnotVelocityEstimator::LocalQuadraticFit: {
      const std::size_t w = options.estimator == KnotVelocityEstimator::Bessel
                                ? 1
                                : static_cast<std::size_t>(options.fit_half_width);
      // A window of 2w+1 knots centred on i, shifted inside [0, last_index].
      std::size_t first = i >= w ? i - w : 0;
      std::size_t last = first + 2 * w;
      if (last > last_index) {
        last = last_index;
        first = last >= 2 * w ? last - 2 * w : 0;
      }
      return {first, last};
    }
  }
  return {i, i};
}

}  // namespace posefair::geometric_splines
