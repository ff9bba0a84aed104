#include "posefair/core/rests_and_turns.hpp"

#include <algorithm>
#include <numbers>

namespace posefair {

RestsAndTurns::RestsAndTurns(const RestsAndTurnsSpec& spec, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto between = [&](double lo, double hi) { return lo + (hi - lo) * uni(rng); };
  Quat q = Quat::Identity();
  for (double t = between(spec.rest_min_s, spec.rest_max_s); t < spec.seconds;) {
    Vec3 axis(gauss(rng), gauss(rng), gauss(rng));
    const double angle = between(spec.angle_min_deg, spec.angle_max_deg) * std::numbers::pi / 180.0;
    const Turn turn{t, between(spec.turn_min_s, spec.turn_max_s), axis.normalized() * angle, q};
    turns_.push_back(turn);
    q = (turn.before * so3::from_rotation_vector(turn.rotation)).normalized();
    t += turn.duration + between(spec.rest_min_s, spec.rest_max_s);
  }
}

Quat RestsAndTurns::at(double t) const {
  Quat at = Quat::Identity();
  for (const Turn& turn : turns_) {
    if (t < turn.start) break;
    const double u = std::min(1.0, (t - turn.start) / turn.duration);
    at = (turn.before * so3::from_rotation_vector(u * u * (3.0 - 2.0 * u) * turn.rotation)).normalized();
  }
  return at;
}

}  // namespace posefair
