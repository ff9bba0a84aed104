// Time to build the quaternion spline of the 7-keyframe example (docs/quaternion-splines.md):
// the paper's 4 variable frames (goal: under 50 ms; the paper: 4 s in 1997), with either
// optimiser, plus the pieces it is made of.
// Run: build/tests/bench/quaternion_spline_bench
#include <benchmark/benchmark.h>

#include "posefair/core/quaternion_spline.hpp"
#include "posefair/core/quaternion_spline_example.hpp"
#include "posefair/core/sampled_rotation_energy.hpp"

namespace posefair {
namespace {

void run(benchmark::State& state, SplineOptimizer method, int frames, int per_round, double alpha) {
  const SplineKeyframes keys = seven_keyframe_example();
  QuaternionSplineOptions o;
  o.alpha = alpha;
  o.variable_frames = frames;
  o.frames_per_round = per_round;
  o.optimizer.method = method;
  double objective = 0.0;
  int evaluations = 0;
  for (auto _ : state) {
    const QuaternionSplineResult r = build_quaternion_spline(keys, o);
    objective = r.stages.back().objective;
    evaluations = 0;
    for (const SplineStage& s : r.stages) evaluations += s.evaluations;
    benchmark::DoNotOptimize(objective);
  }
  state.counters["objective"] = objective;
  state.counters["evaluations"] = evaluations;
}

// The whole pipeline incl. the per-stage statistics (norm deviation, EL error per segment).
void BM_SevenKeys_FourFrames_Lbfgs(benchmark::State& s) { run(s, SplineOptimizer::Lbfgs, 4, 1, 1000.0); }
void BM_SevenKeys_FourFrames_Slsqp(benchmark::State& s) { run(s, SplineOptimizer::Slsqp, 4, 1, 1000.0); }
void BM_SevenKeys_VelocitiesOnly_Lbfgs(benchmark::State& s) { run(s, SplineOptimizer::Lbfgs, 0, 1, 1000.0); }
void BM_SevenKeys_VelocitiesOnly_Slsqp(benchmark::State& s) { run(s, SplineOptimizer::Slsqp, 0, 1, 1000.0); }
void BM_SevenKeys_24FramesOneRound_Alpha1e4_Lbfgs(benchmark::State& s) { run(s, SplineOptimizer::Lbfgs, 24, 24, 1e4); }
void BM_SevenKeys_24FramesOneRound_Alpha1e4_Slsqp(benchmark::State& s) { run(s, SplineOptimizer::Slsqp, 24, 24, 1e4); }
BENCHMARK(BM_SevenKeys_FourFrames_Lbfgs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SevenKeys_FourFrames_Slsqp)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SevenKeys_VelocitiesOnly_Lbfgs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SevenKeys_VelocitiesOnly_Slsqp)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SevenKeys_24FramesOneRound_Alpha1e4_Lbfgs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SevenKeys_24FramesOneRound_Alpha1e4_Slsqp)->Unit(benchmark::kMillisecond);

// One objective + gradient evaluation on the 4-frame curve (11 pieces, 8 points each).
void BM_ObjectiveAndGradient(benchmark::State& state) {
  QuaternionSplineOptions o;
  const QuaternionSplineResult r = build_quaternion_spline(seven_keyframe_example(), o);
  const SplineObjective objective(1000.0, 8);
  ObjectiveGradient g;
  for (auto _ : state) benchmark::DoNotOptimize(objective.value_and_gradient(r.spline.curve, g));
}
BENCHMARK(BM_ObjectiveAndGradient)->Unit(benchmark::kMicrosecond);

// The slerp chain through the same keys, sampled at 100 Hz (601 samples): the cheap baseline.
void BM_SlerpChain_100Hz(benchmark::State& state) {
  const SplineKeyframes k = seven_keyframe_example();
  const std::vector<double> t = uniform_times(0.0, 6.0, 0.01);
  for (auto _ : state) benchmark::DoNotOptimize(slerp_chain(k.time, k.orientation, t));
}
BENCHMARK(BM_SlerpChain_100Hz)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace posefair

BENCHMARK_MAIN();
