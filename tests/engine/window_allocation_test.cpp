// FairingWindow's promise that push() and flush() never allocate. This binary links
// tests/support/counting_allocator.cpp, which replaces the global operator new/delete with
// counting versions, so it must not share an executable with other tests.
#include <cmath>
#include <cstddef>
#include <new>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/synthetic_motion.hpp"

#include "../support/counting_allocator.hpp"

namespace posefair {
namespace {

using testing::allocations;
using testing::keep;
using testing::live_bytes;

TEST(WindowAllocation, TheCounterSeesAllocations) {
  // Without this the zero below would prove nothing.
  const std::size_t before = allocations();
  auto* v = new std::vector<double>(100);
  keep(v);
  auto* aligned = new Eigen::Matrix4d[3];
  keep(aligned);
  auto* over_aligned = new (std::align_val_t{64}) double[5];
  keep(over_aligned);
  delete v;
  delete[] aligned;
  ::operator delete[](over_aligned, std::align_val_t{64});
  EXPECT_GE(allocations() - before, 4u);  // the vector, its buffer, the array, the aligned block
  const std::ptrdiff_t live = live_bytes();
  auto* block = new double[1000];
  keep(block);
  EXPECT_EQ(live_bytes() - live, static_cast<std::ptrdiff_t>(1000 * sizeof(double)));
  delete[] block;
  EXPECT_EQ(live_bytes(), live);
}

// A stream of `n` samples with positions, continuing in time from `t0`.
std::vector<Sample> stream(std::size_t n, double t0, std::uint64_t seed) {
  SyntheticMotionSpec spec;
  spec.samples = n;
  spec.cycles = static_cast<double>(n) / 300.0;
  spec.rotation_noise = 0.04;
  spec.position_noise = 8.0;
  spec.seed = seed;
  const SyntheticMotion m = make_synthetic_motion(spec);
  std::vector<Sample> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i].sequence = i;
    out[i].time = t0 + m.noisy.time[i];
    out[i].orientation = m.noisy.orientation[i];
    out[i].position = m.noisy.position[i];
    out[i].flags = kHasPosition;
  }
  return out;
}

struct Case {
  const char* name;
  WindowSolver solver;
  BoundPolicy bound;
  bool defaults = false;  // the engine's defaults: the rate is measured, and W, the rows and
                          // the adaptation are set, inside the measured run
  bool gyro = false;      // the samples carry a gyro: gyro-aided fairing with its estimates
  bool held = false;      // each measurement repeated 4 times: the window at the source's rate, repeats carried forward
};

TEST(WindowAllocation, SteadyStatePushAndFlushNeverAllocate) {
  const Case cases[] = {
      {"linear", WindowSolver::Linear, BoundPolicy::Sample},
      {"gauss-newton", WindowSolver::GaussNewton, BoundPolicy::Sample},
      {"gauss-newton window bound", WindowSolver::GaussNewton, BoundPolicy::Window},
      {"sweeps", WindowSolver::DampedSweeps, BoundPolicy::Sample},
      {"sweeps window bound", WindowSolver::DampedSweeps, BoundPolicy::Window},
      {"defaults (adaptive)", WindowSolver::Linear, BoundPolicy::Sample, true},
      {"defaults, gyro-aided", WindowSolver::Linear, BoundPolicy::Sample, true, true},
      {"defaults, a stream read faster than its source", WindowSolver::Linear, BoundPolicy::Sample, true, false, true},
  };
  constexpr std::size_t kWarmUp = 300, kMeasured = 10000;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    WindowConfig config;
    config.solver = c.solver;
    config.bound = c.bound;
    config.order = 3;
    config.window = 32;
    config.lag = 4;
    config.iterations = 3;
    config.continuity = 0.5;
    config.smoothing_r = smoothing_for_cutoff(4.0, 100.0, 3);
    config.smoothing_t = config.smoothing_r;
    if (c.defaults) config = WindowConfig{};
    config.epsilon_r = 0.02;  // tight enough that the projections run
    config.epsilon_t = 4.0;
    FairingWindow w(config);
    const std::size_t bytes = w.memory_bytes();
    EXPECT_GT(bytes, 0u);

    // Everything the measured loop touches exists before it starts.
    std::vector<Sample> warm = stream(c.defaults ? 3 : kWarmUp, 0.0, 1);
    std::vector<Sample> measured = stream(kMeasured, warm.back().time + 0.01, 2);
    for (std::size_t i = 4000; i < measured.size(); ++i) measured[i].time += 1.0;  // a gap: restart
    if (c.gyro)
      for (auto* part : {&warm, &measured})
        for (std::size_t i = 0; i < part->size(); ++i) {
          (*part)[i].gyro = Vec3(0.3 * std::sin(0.01 * static_cast<double>(i)), 0.2, -0.1);
          (*part)[i].flags |= kHasGyro;
        }
    if (c.held)
      for (auto* part : {&warm, &measured})
        for (std::size_t i = 0; i < part->size(); ++i) {
          const Sample& shown = (*part)[i - i % 4];
          (*part)[i].orientation = shown.orientation;
          (*part)[i].position = shown.position;
        }
    Sample bad = measured[5000];
    bad.orientation.coeffs() *= 2.0;  // rejected by the gate
    std::vector<FairedPose> out(static_cast<std::size_t>(w.max_outputs_per_push()));

    std::size_t emitted = 0;
    for (const Sample& s : warm) emitted += static_cast<std::size_t>(w.push(s, out));

    // The measured run: no gtest assertions inside (they may allocate), only plain bookkeeping.
    bool memory_changed = false;
    const std::size_t before = allocations();
    for (std::size_t i = 0; i < measured.size(); ++i) {
      emitted += static_cast<std::size_t>(w.push(measured[i], out));
      if (i == 5000) emitted += static_cast<std::size_t>(w.push(bad, out));
      if (i == 6999) emitted += static_cast<std::size_t>(w.flush(out));
      if (i % 1000 == 0) memory_changed = memory_changed || w.memory_bytes() != bytes;
    }
    emitted += static_cast<std::size_t>(w.flush(out));
    const std::size_t during = allocations() - before;

    EXPECT_EQ(during, 0u) << "push()/flush() allocated";
    EXPECT_FALSE(memory_changed);
    EXPECT_EQ(w.memory_bytes(), bytes);
    // The run did what it was meant to: everything emitted once, one gap restart, a rejection,
    // and the bound was exercised.
    EXPECT_EQ(emitted, warm.size() + kMeasured);
    if (c.defaults) {
      EXPECT_GT(w.state().rate_hz, 0.0) << "the rate was never measured";
    }
    if (c.gyro) {
      EXPECT_TRUE(w.state().gyro.active);
      EXPECT_GT(w.state().gyro.intervals, kMeasured / 2);
    }
    if (c.held) {
      EXPECT_GT(w.counters().repeated, kMeasured / 2);
      EXPECT_GE(w.counters().restarts, 2u);  // the gap, and starting afresh at the source's rate
    } else {
      EXPECT_EQ(w.counters().restarts, 1u);
    }
    EXPECT_EQ(w.gate_counters().rejected_non_unit, 1u);
    EXPECT_GT(w.counters().clamped, 0u);
  }
}

TEST(WindowAllocation, MemoryGrowsWithTheWindowAndIsFixedAtConstruction) {
  WindowConfig small, large;
  small.window = 8;
  large.window = 64;
  const FairingWindow a(small), b(large);
  EXPECT_GT(a.memory_bytes(), sizeof(FairingWindow));
  EXPECT_GT(b.memory_bytes(), a.memory_bytes());
}

}  // namespace
}  // namespace posefair

namespace posefair {
namespace {

// What the constructor keeps on the heap, measured by the counting allocator, against what
// memory_bytes() reports ("bytes held for this stream, all of it allocated at construction").
struct Held {
  std::ptrdiff_t heap;
  std::size_t reported;
};

Held held_by(const WindowConfig& c) {
  const std::ptrdiff_t before = live_bytes();
  auto* w = new FairingWindow(c);  // on the heap, so sizeof(FairingWindow) is counted as well
  const Held h{live_bytes() - before, w->memory_bytes()};
  delete w;
  return h;
}

TEST(WindowAllocation, MemoryBytesAccountsForTheHeapTheWindowHolds) {
  // Every solver; the linear solver (and any solver with continuity > 0) also keeps the
  // precomputed emission rows, O(W²) doubles, which memory_bytes() once left out (43,832
  // reported against 58,624 held at W = 32).
  struct Case {
    WindowSolver solver;
    double continuity;
  };
  for (const Case& cs : {Case{WindowSolver::Linear, 0.0}, Case{WindowSolver::Linear, 0.5}, Case{WindowSolver::GaussNewton, 0.0},
                         Case{WindowSolver::GaussNewton, 0.5}, Case{WindowSolver::DampedSweeps, 0.0}}) {
    for (int window : {8, 32, 128}) {
      WindowConfig c;
      c.solver = cs.solver;
      c.continuity = cs.continuity;
      c.window = window;
      c.lag = 2;
      if (cs.continuity > 0.0 || cs.solver == WindowSolver::GaussNewton) c.smoothing_r = c.smoothing_t = 100.0;
      const Held h = held_by(c);
      SCOPED_TRACE("solver " + std::to_string(static_cast<int>(cs.solver)) + " continuity " + std::to_string(cs.continuity) +
                   " window " + std::to_string(window));
      EXPECT_GE(static_cast<std::ptrdiff_t>(h.reported), h.heap);
      EXPECT_LE(static_cast<std::ptrdiff_t>(h.reported), h.heap + h.heap / 10);
    }
  }
  // The defaults: storage for max_window samples and every smoothing level.
  const Held h = held_by(WindowConfig{});
  EXPECT_GE(static_cast<std::ptrdiff_t>(h.reported), h.heap);
  EXPECT_LE(static_cast<std::ptrdiff_t>(h.reported), h.heap + h.heap / 10);
}

}  // namespace
}  // namespace posefair
