#include "posefair/core/fairing_study.hpp"

#include <algorithm>
#include <limits>

#include "posefair/core/difference_operators.hpp"

namespace posefair {
namespace {

double angular_acceleration(std::span<const Quat> q, double dt) {
  const auto w2 = orientation_differences(q, 2);
  double a = 0.0;
  for (const Vec3& w : w2) a += 2.0 * w.norm() / static_cast<double>(w2.size()) / (dt * dt);
  return a;
}

FairingTracePoint measure(int k, const SyntheticMotion& motion, std::span<const Quat> q,
                          std::span<const Vec3> p, int order) {
  FairingTracePoint t;
  t.iteration = k;
  const std::size_t n = q.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double e_in = so3::dist(motion.noisy.orientation[i], q[i]);
    t.mean_error_to_input += e_in / static_cast<double>(n);
    t.max_error_to_input = std::max(t.max_error_to_input, e_in);
    t.mean_error_to_truth += so3::dist(motion.truth.orientation[i], q[i]) / static_cast<double>(n);
  }
  const double dt = motion.noisy.time.size() > 1 ? motion.noisy.time[1] - motion.noisy.time[0] : 1.0;
  t.mean_angular_acceleration = angular_acceleration(q, dt);
  t.rotational_energy = rotational_energy(q, order);
  if (!p.empty()) {
    for (std::size_t i = 0; i < n; ++i)
      t.mean_position_error_to_truth += (motion.truth.position[i] - p[i]).norm() / static_cast<double>(n);
    const auto d2 = position_differences(p, 2);
    for (const Vec3& d : d2) t.mean_acceleration += d.norm() / static_cast<double>(d2.size()) / (dt * dt);
  }
  return t;
}

}  // namespace

double mean_angular_acceleration(const PoseSequence& poses) {
  std::vector<Quat> q = poses.orientation;
  so3::make_continuous(q);
  return angular_acceleration(q, poses.time.size() > 1 ? poses.time[1] - poses.time[0] : 1.0);
}

std::vector<BoundedRun> bounded_runs(const SyntheticMotionSpec& spec, int seeds, const FairingParams& params) {
  std::vector<BoundedRun> runs;
  for (int s = 1; s <= seeds; ++s) {
    SyntheticMotionSpec one = spec;
    one.seed = static_cast<std::uint64_t>(s);
    const SyntheticMotion motion = make_synthetic_motion(one);
    const FairingResult r = fair(motion.noisy, params);
    BoundedRun run{s, r.iterations, r.stop, 0, 0, -1};
    if (r.stop == StopReason::Bound) {
      // The iterate the loop refused: one sweep more, without the bounds.
      FairingParams free = params;
      free.epsilon_r = free.epsilon_t = std::numeric_limits<double>::infinity();
      free.max_iterations = r.iterations + 1;
      const FairingResult next = fair(motion.noisy, free);
      for (std::size_t i = 0; i < motion.noisy.size(); ++i) {
        const bool rot = !(so3::dist(motion.noisy.orientation[i], next.poses.orientation[i]) < params.epsilon_r);
        const bool pos = motion.noisy.has_position() &&
                         !((next.poses.position[i] - motion.noisy.position[i]).norm() < params.epsilon_t);
        run.breaking_rotation += rot;
        run.breaking_position += pos;
        if ((rot || pos) && run.first_breaking < 0) run.first_breaking = static_cast<std::ptrdiff_t>(i);
      }
    }
    runs.push_back(run);
  }
  return runs;
}

FairedMotionStages faired_motion_stages(const SyntheticMotionSpec& spec, const FairingParams& params) {
  const SyntheticMotion motion = make_synthetic_motion(spec);
  FairedMotionStages st{motion.truth, motion.noisy, motion.noisy, {}};
  st.faired = fair(motion.noisy, params).poses;
  // Translation and rotation sweeps do not interact: the positions of the full run are those
  // of fairing positions alone.
  st.translation_faired.position = st.faired.position;
  return st;
}

std::vector<FairingTracePoint> trace_fairing(const SyntheticMotion& motion, const FairingParams& params) {
  std::vector<FairingTracePoint> trace;
  std::vector<Quat> q0 = motion.noisy.orientation;
  so3::make_continuous(q0);
  trace.push_back(measure(0, motion, q0, motion.noisy.position, params.order));
  fair(motion.noisy, params, [&](int k, std::span<const Quat> q, std::span<const Vec3> p) {
    trace.push_back(measure(k, motion, q, p, params.order));
  });
  return trace;
}

std::vector<FairingTracePoint> mean_trace(const SyntheticMotionSpec& spec, int seeds, const FairingParams& params) {
  std::vector<FairingTracePoint> mean;
  for (int s = 1; s <= seeds; ++s) {
    SyntheticMotionSpec one = spec;
    one.seed = static_cast<std::uint64_t>(s);
    const auto t = trace_fairing(make_synthetic_motion(one), params);
    // With finite bounds traces may differ in length: keep the common prefix.
    if (mean.empty()) mean.resize(t.size());
    if (t.size() < mean.size()) mean.resize(t.size());
    const double w = 1.0 / seeds;
    for (std::size_t k = 0; k < mean.size(); ++k) {
      mean[k].iteration = t[k].iteration;
      mean[k].mean_error_to_input += w * t[k].mean_error_to_input;
      mean[k].mean_error_to_truth += w * t[k].mean_error_to_truth;
      mean[k].max_error_to_input += w * t[k].max_error_to_input;
      mean[k].mean_angular_acceleration += w * t[k].mean_angular_acceleration;
      mean[k].mean_position_error_to_truth += w * t[k].mean_position_error_to_truth;
      mean[k].mean_acceleration += w * t[k].mean_acceleration;
      mean[k].rotational_energy += w * t[k].rotational_energy;
    }
  }
  return mean;
}

}  // namespace posefair
