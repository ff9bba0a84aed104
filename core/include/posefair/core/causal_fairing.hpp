#pragma once
// A whole recorded sequence through the real-time engine, exactly as the daemon runs it:
// samples pushed one by one into a FairingWindow, the lagged tail flushed at the end.
// Used by `posefair fair --causal`, the quality benchmark and tests, so all three run the
// same code as a live stream.
#include <cstdint>
#include <vector>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/pose_sequence.hpp"

namespace posefair {

struct CausalResult {
  PoseSequence poses;            // one pose per input sample; dropped/rejected ones keep the input
  std::vector<bool> emitted;     // false where the engine dropped or rejected the sample
  WindowCounters counters;
  GateCounters gate;
  EngineState state;             // the engine's rate, window and adaptation at the end
  double max_dist_r = 0.0;       // max dist(output, input) on S³ over emitted samples
  double max_deviation_t = 0.0;
};

CausalResult fair_causal(const PoseSequence& input, const WindowConfig& config);

}  // namespace posefair
