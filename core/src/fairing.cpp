#include "posefair/core/fairing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "posefair/core/difference_operators.hpp"
#include "posefair/core/fairing_sweep.hpp"

namespace posefair {

std::string_view to_string(StopReason r) {
  switch (r) {
    case StopReason::IterationCap: return "iteration cap";
    case StopReason::Bound: return "deviation bound";
    case StopReason::Converged: return "converged";
  }
  return "?";
}

void validate(const FairingParams& p) {
  auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
  if (p.order != 2 && p.order != 3) bad("order must be 2 or 3, got " + std::to_string(p.order));
  if (!(p.lambda_t > 0.0 && p.lambda_t <= 1.0)) bad("lambda_t must be in (0, 1], got " + std::to_string(p.lambda_t));
  if (!(p.lambda_r > 0.0 && p.lambda_r <= 1.0)) bad("lambda_r must be in (0, 1], got " + std::to_string(p.lambda_r));
  if (!(p.epsilon_t > 0.0)) bad("epsilon_t must be positive, got " + std::to_string(p.epsilon_t));
  if (!(p.epsilon_r > 0.0)) bad("epsilon_r must be positive, got " + std::to_string(p.epsilon_r));
  if (p.max_iterations < 0) bad("the iteration cap must be >= 0, got " + std::to_string(p.max_iterations));
  if (!(p.step_tolerance >= 0.0)) bad("step_tolerance must be >= 0");
}

FairingResult fair(const PoseSequence& input, const FairingParams& params, const FairingObserver& observer) {
  validate(params);
  const std::size_t n = input.size();
  const int m = params.order;
  if (n < static_cast<std::size_t>(min_samples_for_order(m)))
    throw std::invalid_argument("order-" + std::to_string(m) + " fairing needs at least " +
                                std::to_string(min_samples_for_order(m)) + " samples, got " +
                                std::to_string(n));
  const bool with_p = input.has_position();
  if (with_p && input.position.size() != n)
    throw std::invalid_argument("the sequence has " + std::to_string(n) + " orientations but " +
                                std::to_string(input.position.size()) + " positions");

  // q0: the measurement, hemisphere-continuous so differences are short arcs.
  std::vector<Quat> q0(input.orientation.begin(), input.orientation.end());
  for (Quat& q : q0) q.normalize();
  so3::make_continuous(q0);
  const std::vector<Vec3>& p0 = input.position;

  FairingResult r;
  r.rotational_energy_before = rotational_energy(q0, m);
  if (with_p) r.translational_energy_before = translational_energy(p0, m);

  // The sweeps run on arrays of components (fairing_sweep.hpp); quaternions are built only
  // for an observer and for the result.
  FairingSweep sweep(params, q0, p0);
  std::vector<Quat> q;
  std::vector<Vec3> p;
  r.stop = StopReason::IterationCap;
  for (int k = 0; k < params.max_iterations; ++k) {
    // Eq. 20 on the candidate: reject it (keep the last good iterate) if any sample breaks it.
    const SweepOutcome o = sweep.sweep();
    if (!o.within) {
      r.stop = StopReason::Bound;
      break;
    }
    // With no tolerance only a sweep that moves nothing converges; the exact step is needed
    // only to compare it with a tolerance.
    const bool converged = params.step_tolerance > 0.0 ? sweep.step() <= params.step_tolerance : !o.moved;
    sweep.accept();
    r.iterations = k + 1;
    if (observer) {
      sweep.current(q, p);
      observer(r.iterations, q, p);
    }
    if (converged) {
      r.stop = StopReason::Converged;
      break;
    }
  }
  sweep.current(q, p);

  r.rotational_energy_after = rotational_energy(q, m);
  if (with_p) r.translational_energy_after = translational_energy(p, m);
  for (std::size_t i = 0; i < n; ++i) {
    r.max_dist_r = std::max(r.max_dist_r, so3::dist(q0[i], q[i]));
    if (with_p) r.max_deviation_t = std::max(r.max_deviation_t, (p[i] - p0[i]).norm());
  }

  // Give each output the sign its input sample had, so files compare column by column.
  r.poses.time = input.time;
  r.poses.orientation.resize(n);
  for (std::size_t i = 0; i < n; ++i) r.poses.orientation[i] = so3::aligned_to(q[i], input.orientation[i]);
  r.poses.position = std::move(p);
  return r;
}

}  // namespace posefair
