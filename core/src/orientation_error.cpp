// BROAD's error measures (orientation_error.hpp).
#include "posefair/core/orientation_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace posefair {

OrientationError earth_frame_error(const Quat& estimate, const Quat& reference) {
  const Quat e = (estimate.normalized() * reference.normalized().conjugate()).normalized();
  OrientationError out;
  out.total = 2.0 * std::acos(std::clamp(std::abs(e.w()), 0.0, 1.0));
  out.heading = 2.0 * std::atan(std::abs(e.z() / e.w()));
  out.inclination = 2.0 * std::acos(std::clamp(std::sqrt(e.w() * e.w() + e.z() * e.z()), 0.0, 1.0));
  return out;
}

OrientationRmse orientation_rmse(std::span<const Quat> estimate, std::span<const Quat> reference,
                                 std::span<const std::uint8_t> scored) {
  if (estimate.size() != reference.size() || estimate.size() != scored.size())
    throw std::invalid_argument("orientation_rmse: estimate, reference and scored differ in length");
  double total = 0.0, heading = 0.0, inclination = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < estimate.size(); ++k) {
    if (scored[k] == 0) continue;
    const OrientationError e = earth_frame_error(estimate[k], reference[k]);
    total += e.total * e.total;
    heading += e.heading * e.heading;
    inclination += e.inclination * e.inclination;
    ++n;
  }
  OrientationRmse out;
  out.samples = n;
  const double deg = 180.0 / M_PI;
  const double count = n > 0 ? static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
  out.total_deg = std::sqrt(total / count) * deg;
  out.heading_deg = std::sqrt(heading / count) * deg;
  out.inclination_deg = std::sqrt(inclination / count) * deg;
  return out;
}

}  // namespace posefair
