// Time to build the quaternion spline of the 7-keyframe example (docs/quaternion-splines.md):
// the paper's 4 variable frames (goal: under 50 ms; the paper: 4 s in 1997), with either
// optimiser, plus the pieces it is made of.
// Run: build/tests/bench/quaternion_spline_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <functional>
#include <vector>

#include "posefair/core/knot_velocity.hpp"
#include "posefair/core/quaternion_spline.hpp"
#include "posefair/core/quaternion_spline_example.hpp"
#include "posefair/core/sampled_rotation_energy.hpp"
#include "posefair/core/sphere_geometric_spline.hpp"

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

// Comparison on the same keys (docs/quaternion-splines.md): each curve built and sampled at
// 100 Hz (601 samples); counters: the sampled covariant energy E_Δ at 100 Hz and 1000 Hz.
void report_energy(benchmark::State& state, const std::function<std::vector<Quat>(const std::vector<double>&)>& sample) {
  for (double rate : {100.0, 1000.0}) {
    const std::vector<double> t = uniform_times(0.0, 6.0, 1.0 / rate);
    state.counters[rate == 100.0 ? "energy_100Hz" : "energy_1000Hz"] = sampled_covariant_energy(sample(t), 1.0 / rate);
  }
}

void BM_Compare_SlerpChain(benchmark::State& state) {
  const SplineKeyframes k = seven_keyframe_example();
  auto sample = [&](const std::vector<double>& t) { return slerp_chain(k.time, k.orientation, t); };
  const std::vector<double> t = uniform_times(0.0, 6.0, 0.01);
  for (auto _ : state) benchmark::DoNotOptimize(sample(t));
  report_energy(state, sample);
}
BENCHMARK(BM_Compare_SlerpChain)->Unit(benchmark::kMillisecond);

// The C² geometric spline on S³ (Rodrigues, Silva Leite & Jakubiak, eq. 22, family
// geometric_splines) through the same keys: zero velocity at the ends like the example,
// interior knot velocities by the Bessel estimator on log coordinates.
void BM_Compare_GeometricSplineC2(benchmark::State& state) {
  using P = geometric_splines::SpherePoint<4>;
  const SplineKeyframes k = seven_keyframe_example();
  auto build = [&] {
    std::vector<P> p;
    for (const Quat& q : k.orientation) p.push_back(to_vec4(q));
    std::vector<P> v(p.size(), P::Zero());
    for (std::size_t i = 1; i + 1 < p.size(); ++i) {
      const double dt[3] = {k.time[i - 1] - k.time[i], 0.0, k.time[i + 1] - k.time[i]};
      const P x[3] = {geometric_splines::sphere_log<4>(p[i], p[i - 1]), P::Zero(),
                      geometric_splines::sphere_log<4>(p[i], p[i + 1])};
      v[i] = geometric_splines::estimate_knot_velocity<4>(geometric_splines::KnotVelocityEstimator::Bessel, dt, x);
    }
    return geometric_splines::SphereGeometricSpline<4>(k.time, p, v, 2);
  };
  auto sample = [](const geometric_splines::SphereGeometricSpline<4>& s, const std::vector<double>& t) {
    std::vector<Quat> out;
    out.reserve(t.size());
    for (double x : t) out.push_back(to_quat(s.evaluate(std::min(x, s.end_time()))));
    return out;
  };
  const std::vector<double> t = uniform_times(0.0, 6.0, 0.01);
  for (auto _ : state) benchmark::DoNotOptimize(sample(build(), t));
  const auto spline = build();
  report_energy(state, [&](const std::vector<double>& times) { return sample(spline, times); });
}
BENCHMARK(BM_Compare_GeometricSplineC2)->Unit(benchmark::kMillisecond);

// This optimiser (4 variable frames), built and sampled.
void BM_Compare_CovariantSpline4Frames(benchmark::State& state) {
  const SplineKeyframes k = seven_keyframe_example();
  auto sample = [](const HermiteCurve4& c, const std::vector<double>& t) {
    std::vector<Quat> out;
    out.reserve(t.size());
    for (double x : t) out.push_back(to_quat(c.position(x).normalized()));
    return out;
  };
  const std::vector<double> t = uniform_times(0.0, 6.0, 0.01);
  QuaternionSplineOptions o;
  for (auto _ : state) benchmark::DoNotOptimize(sample(build_quaternion_spline(k, o).spline.curve, t));
  const HermiteCurve4 curve = build_quaternion_spline(k, o).spline.curve;
  report_energy(state, [&](const std::vector<double>& times) { return sample(curve, times); });
}
BENCHMARK(BM_Compare_CovariantSpline4Frames)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair

BENCHMARK_MAIN();
