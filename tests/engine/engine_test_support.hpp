#pragma once
// Helpers shared by the FairingWindow tests: turning pose sequences into Sample streams,
// running a window over a stream while checking the per-push output limit, and error measures.
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/pose_sequence.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair::testing {

inline const char* solver_name(WindowSolver s) {
  switch (s) {
    case WindowSolver::Linear: return "linear";
    case WindowSolver::GaussNewton: return "gauss-newton";
    case WindowSolver::DampedSweeps: return "sweeps";
  }
  return "?";
}

inline const char* bound_name(BoundPolicy b) { return b == BoundPolicy::Sample ? "sample" : "window"; }

// Sample i gets sequence first_sequence + i and the sequence's time; positions if it has them.
inline std::vector<Sample> samples_from(const PoseSequence& seq, std::uint32_t stream_id = 7,
                                        std::uint64_t first_sequence = 1000) {
  std::vector<Sample> out(seq.size());
  for (std::size_t i = 0; i < seq.size(); ++i) {
    Sample& s = out[i];
    s.stream_id = stream_id;
    s.sequence = first_sequence + i;
    s.time = seq.time[i];
    s.orientation = seq.orientation[i];
    if (seq.has_position()) {
      s.position = seq.position[i];
      s.flags |= kHasPosition;
    }
  }
  return out;
}

inline std::vector<Sample> samples_from(std::span<const Quat> q, double rate_hz = 100.0) {
  std::vector<Sample> out(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    out[i].sequence = i;
    out[i].time = static_cast<double>(i) / rate_hz;
    out[i].orientation = q[i];
  }
  return out;
}

inline SyntheticMotion noisy_motion(std::uint64_t seed, bool with_position, std::size_t n = 400,
                                    double rotation_noise = 0.05, double position_noise = 10.0,
                                    double cycles = 4.0) {
  SyntheticMotionSpec spec;
  spec.samples = n;
  spec.sample_rate_hz = 100.0;
  spec.cycles = cycles;
  spec.rotation_noise = rotation_noise;
  spec.with_position = with_position;
  spec.position_noise = position_noise;
  spec.seed = seed;
  return make_synthetic_motion(spec);
}

// Pushes every sample (then flushes, if asked) and collects what comes out. Each call gets a
// buffer of exactly max_outputs_per_push() poses (heap-allocated, so an overrun is visible to
// AddressSanitizer) and must report a count within it.
inline std::vector<FairedPose> run(FairingWindow& w, std::span<const Sample> in, bool flush = true,
                                   std::vector<int>* counts = nullptr) {
  std::vector<FairedPose> all;
  const int cap = w.max_outputs_per_push();
  std::vector<FairedPose> buf(static_cast<std::size_t>(cap));
  auto take = [&](int k) {
    EXPECT_GE(k, 0);
    EXPECT_LE(k, cap);
    if (counts) counts->push_back(k);
    for (int i = 0; i < k && i < cap; ++i) all.push_back(buf[static_cast<std::size_t>(i)]);
  };
  for (const Sample& s : in) take(w.push(s, buf));
  if (flush) take(w.flush(buf));
  return all;
}

inline std::vector<FairedPose> run(const WindowConfig& c, std::span<const Sample> in, bool flush = true) {
  FairingWindow w(c);
  return run(w, in, flush);
}

// The config the accuracy tests use: a sensible low-pass for 100 Hz data.
inline WindowConfig smoothing_config(WindowSolver solver, int order, int lag, int iterations = 3) {
  WindowConfig c;
  c.solver = solver;
  c.order = order;
  c.lag = lag;
  c.window = 32;
  c.iterations = iterations;
  c.smoothing_r = smoothing_for_cutoff(4.0, 100.0, order);
  c.smoothing_t = c.smoothing_r;
  return c;
}

}  // namespace posefair::testing
