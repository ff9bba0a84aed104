#include "posefair/core/causal_fairing.hpp"

#include <algorithm>

namespace posefair {

CausalResult fair_causal(const PoseSequence& input, const WindowConfig& config) {
  FairingWindow window(config);
  std::vector<FairedPose> out(static_cast<std::size_t>(window.max_outputs_per_push()));
  CausalResult r;
  r.poses = input;
  r.emitted.assign(input.size(), false);
  const bool with_p = input.has_position();

  auto take = [&](int count) {
    for (int k = 0; k < count; ++k) {
      const FairedPose& f = out[static_cast<std::size_t>(k)];
      const auto i = static_cast<std::size_t>(f.sequence);
      // Each output keeps the sign its input sample had, as the batch tool does.
      r.poses.orientation[i] = so3::aligned_to(f.orientation, input.orientation[i]);
      if (with_p) r.poses.position[i] = f.position;
      r.poses.time[i] = f.time;  // later than the input's with a horizon: the time it predicts
      r.emitted[i] = true;
      r.max_dist_r = std::max(r.max_dist_r, so3::dist(f.orientation, input.orientation[i]));
      if (with_p) r.max_deviation_t = std::max(r.max_deviation_t, (f.position - input.position[i]).norm());
    }
  };
  for (std::size_t i = 0; i < input.size(); ++i) {
    Sample s;
    s.sequence = i;
    s.time = input.time[i];
    s.orientation = input.orientation[i];
    if (with_p) {
      s.position = input.position[i];
      s.flags |= kHasPosition;
    }
    take(window.push(s, out));
  }
  take(window.flush(out));
  r.counters = window.counters();
  r.gate = window.gate_counters();
  r.state = window.state();
  return r;
}

}  // namespace posefair
