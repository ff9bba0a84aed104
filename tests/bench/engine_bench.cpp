// Real-time engine cost per sample (orientation only unless named), against One Euro in the
// same run. docs/engine.md reports these numbers. Run: build/tests/bench/engine_bench
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/one_euro_filter.hpp"
#include "posefair/core/pose_sequence.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair {
namespace {

const SyntheticMotion& stream(bool with_position) {
  static const SyntheticMotion plain = [] {
    SyntheticMotionSpec s;
    s.samples = 20000;
    s.sample_rate_hz = 1000.0;
    s.cycles = 10.0;
    s.with_position = false;
    return make_synthetic_motion(s);
  }();
  static const SyntheticMotion posed = [] {
    SyntheticMotionSpec s;
    s.samples = 20000;
    s.sample_rate_hz = 1000.0;
    s.cycles = 10.0;
    return make_synthetic_motion(s);
  }();
  return with_position ? posed : plain;
}

// A tracker lying still: 1 kHz, noise of 0.01 rad per axis.
const PoseSequence& still_stream() {
  static const PoseSequence still = [] {
    std::mt19937_64 rng(1);
    std::normal_distribution<double> noise(0.0, 0.01);
    PoseSequence p;
    for (int i = 0; i < 20000; ++i) {
      p.time.push_back(i * 0.001);
      p.orientation.push_back(so3::from_rotation_vector(Vec3(noise(rng), noise(rng), noise(rng))));
    }
    return p;
  }();
  return still;
}

void run_window(benchmark::State& state, WindowConfig c, const PoseSequence& input, bool with_position) {
  FairingWindow w(c);
  std::vector<FairedPose> out(static_cast<std::size_t>(w.max_outputs_per_push()));
  std::size_t i = 0;
  double t = 0.0;
  for (auto _ : state) {
    Sample s;
    s.time = t;
    t += 0.001;
    s.orientation = input.orientation[i];
    if (with_position) {
      s.position = input.position[i];
      s.flags = kHasPosition;
    }
    benchmark::DoNotOptimize(w.push(s, out));
    benchmark::DoNotOptimize(out[0].orientation);
    if (++i == input.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["bytes_per_stream"] = static_cast<double>(w.memory_bytes());
}

// Linear solver: window W, order m, lag, continuity.
void BM_Linear(benchmark::State& state) {
  WindowConfig c;
  c.window = static_cast<int>(state.range(0));
  c.order = static_cast<int>(state.range(1));
  c.continuity = static_cast<double>(state.range(2));
  c.smoothing_r = c.smoothing_t = smoothing_for_cutoff(4.0, 1000.0, c.order);
  run_window(state, c, stream(state.range(3) != 0).noisy, state.range(3) != 0);
}

// The defaults (adapted smoothing, W = 0.5 s at 1 kHz capped at 128), optionally with
// positions (two channels adapted) or a prediction horizon of 20 ms.
void BM_Defaults(benchmark::State& state) {
  WindowConfig c;
  if (state.range(1) != 0) c.horizon_s = 0.02;
  run_window(state, c, stream(state.range(0) != 0).noisy, state.range(0) != 0);
}
BENCHMARK(BM_Defaults)->ArgNames({"pos", "horizon"})->Args({0, 0})->Args({1, 0})->Args({0, 1});

// The defaults on a still stream: at rest, the window's output blended with the rest line
// (rest_line.hpp), against rest_memory 0 (the window's heaviest level alone).
void BM_DefaultsAtRest(benchmark::State& state) {
  WindowConfig c;
  c.adaptation.rest_memory_s = state.range(0) != 0 ? 1.0 : 0.0;
  run_window(state, c, still_stream(), false);
}
BENCHMARK(BM_DefaultsAtRest)->ArgNames({"rest_line"})->Arg(1)->Arg(0);

// The defaults with a lag of one sample, with the outlier guard (on by default,
// outlier_guard.hpp) and without it; with positions, both channels guarded.
void BM_DefaultsWithLag(benchmark::State& state) {
  WindowConfig c;
  c.lag = 1;
  if (state.range(1) == 0) c.outlier_threshold = 0.0;
  run_window(state, c, stream(state.range(0) != 0).noisy, state.range(0) != 0);
}
BENCHMARK(BM_DefaultsWithLag)->ArgNames({"pos", "guard"})->Args({0, 1})->Args({0, 0})->Args({1, 1})->Args({1, 0});
BENCHMARK(BM_Linear)
    ->ArgNames({"W", "m", "kappa", "pos"})
    ->Args({32, 2, 0, 0})  // the old default
    ->Args({16, 2, 0, 0})
    ->Args({64, 2, 0, 0})
    ->Args({128, 2, 0, 0})
    ->Args({32, 3, 0, 0})
    ->Args({32, 2, 1, 0})
    ->Args({32, 2, 0, 1});

// Iterative solvers: W and K (iterations or sweeps).
void BM_GaussNewton(benchmark::State& state) {
  WindowConfig c;
  c.window = static_cast<int>(state.range(0));
  c.iterations = static_cast<int>(state.range(1));
  c.solver = WindowSolver::GaussNewton;
  c.smoothing_r = smoothing_for_cutoff(4.0, 1000.0, 2);
  run_window(state, c, stream(false).noisy, false);
}
BENCHMARK(BM_GaussNewton)->ArgNames({"W", "K"})->Args({16, 1})->Args({32, 1})->Args({32, 2});

void BM_PaperSweeps(benchmark::State& state) {
  WindowConfig c;
  c.window = static_cast<int>(state.range(0));
  c.iterations = static_cast<int>(state.range(1));
  c.solver = WindowSolver::DampedSweeps;
  run_window(state, c, stream(false).noisy, false);
}
BENCHMARK(BM_PaperSweeps)->ArgNames({"W", "K"})->Args({16, 4})->Args({32, 4})->Args({32, 16});

void BM_OneEuro(benchmark::State& state) {
  const auto& m = stream(false);
  QuatOneEuroFilter f(8.0, 0.1, 1.0);
  std::size_t i = 0;
  double t = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.filter(m.noisy.orientation[i], t));
    t += 0.001;
    if (++i == m.noisy.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_OneEuro);

}  // namespace
}  // namespace posefair

BENCHMARK_MAIN();
