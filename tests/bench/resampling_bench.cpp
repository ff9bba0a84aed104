// Live resampling and gap bridging (core/fixed_rate_resampler.hpp, core/gap_bridge.hpp): the
// engine thread's cost per faired pose and per grid pose, and the delay resampling adds, for a
// 100 Hz stream published at 250 Hz and at 90 Hz with each spline order, and with
// pose_interpolation = "matrix-lerp" (Alexa's lerp of the 4x4 transform, rigid_pose_lerp.hpp).
//   build/tests/bench/resampling_bench
// Counters: ns_per_grid_pose, and delay_ms_mean / delay_ms_max = (time of the faired pose that
// completed a grid pose) - (the grid pose's time): what the spline's lookahead adds to the
// fairing window's own delay.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "posefair/core/fixed_rate_resampler.hpp"
#include "posefair/core/gap_bridge.hpp"
#include "posefair/core/rigid_pose_lerp.hpp"

namespace {

using namespace posefair;

FairedPose pose_at(double t) {
  FairedPose p;
  p.time = t;
  p.orientation = so3::from_rotation_vector(Vec3(0.8 * std::sin(1.3 * t), 0.5 * std::cos(0.7 * t), 0.3 * t));
  p.position = Vec3(std::sin(t), 0.5 * t, 0.0);
  p.flags = kHasPosition;
  return p;
}

void resample(benchmark::State& state, const FixedRateResamplerOptions& o) {
  constexpr int kPoses = 1000;
  std::vector<FairedPose> input;
  for (int i = 0; i < kPoses; ++i) input.push_back(pose_at(0.0013 + 0.01 * i));
  double delay_sum = 0.0, delay_max = 0.0;
  std::size_t grid = 0;
  for (auto _ : state) {
    FixedRateResampler r(o);
    std::vector<FairedPose> out(r.max_outputs());
    delay_sum = 0.0;
    delay_max = 0.0;
    grid = 0;
    for (const FairedPose& p : input) {
      const std::size_t n = r.push(p, out);
      for (std::size_t j = 0; j < n; ++j) {
        const double d = p.time - out[j].time;
        delay_sum += d;
        delay_max = std::max(delay_max, d);
      }
      grid += n;
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(grid));
  state.counters["ns_per_grid_pose"] =
      benchmark::Counter(static_cast<double>(grid) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert, benchmark::Counter::OneK::kIs1000);
  state.counters["delay_ms_mean"] = 1000.0 * delay_sum / static_cast<double>(std::max<std::size_t>(grid, 1));
  state.counters["delay_ms_max"] = 1000.0 * delay_max;
}

// args: output rate (Hz), spline order
void BM_ResampleA100HzStream(benchmark::State& state) {
  FixedRateResamplerOptions o;
  o.rate_hz = static_cast<double>(state.range(0));
  o.spline.order = static_cast<int>(state.range(1));
  resample(state, o);
}
BENCHMARK(BM_ResampleA100HzStream)
    ->ArgsProduct({{250, 90}, {1, 2, 3}})
    ->ArgNames({"rate_hz", "k"})
    ->Unit(benchmark::kMicrosecond);

// args: output rate (Hz). pose_interpolation = "matrix-lerp": one logarithm per input interval
// that has a grid time in it, one exponential per grid pose.
void BM_ResampleA100HzStreamMatrixLerp(benchmark::State& state) {
  FixedRateResamplerOptions o;
  o.rate_hz = static_cast<double>(state.range(0));
  o.interpolation = PoseInterpolation::MatrixLerp;
  resample(state, o);
}
BENCHMARK(BM_ResampleA100HzStreamMatrixLerp)->Arg(250)->Arg(90)->ArgName("rate_hz")->Unit(benchmark::kMicrosecond);

// One interval prepared (a matrix logarithm), and one pose in it (an exponential and a product),
// for two poses of the 100 Hz stream 10 ms apart.
void BM_RigidPoseLerpPrepare(benchmark::State& state) {
  const FairedPose a = pose_at(0.5), b = pose_at(0.51);
  RigidPoseLerp lerp;
  for (auto _ : state) benchmark::DoNotOptimize(lerp.prepare(a.orientation, a.position, b.orientation, b.position));
}
BENCHMARK(BM_RigidPoseLerpPrepare)->Unit(benchmark::kNanosecond);
void BM_RigidPoseLerpEvaluate(benchmark::State& state) {
  const FairedPose a = pose_at(0.5), b = pose_at(0.51);
  RigidPoseLerp lerp;
  lerp.prepare(a.orientation, a.position, b.orientation, b.position);
  Quat q;
  Vec3 p;
  double f = 0.0;
  for (auto _ : state) {
    lerp.at(f, q, p);
    benchmark::DoNotOptimize(q);
    benchmark::DoNotOptimize(p);
    f = f > 0.9 ? 0.0 : f + 0.1;
  }
}
BENCHMARK(BM_RigidPoseLerpEvaluate)->Unit(benchmark::kNanosecond);

// A 100 Hz stream with a 60 ms dropout every second: cost per input sample through the bridge.
// arg: 0 = spline, 1 = matrix-lerp
void BM_BridgeA100HzStreamWithDropouts(benchmark::State& state) {
  GapBridgeOptions o;
  o.max_gap = 0.1;
  o.interpolation = state.range(0) ? PoseInterpolation::MatrixLerp : PoseInterpolation::Spline;
  std::vector<Sample> input;
  for (int i = 0; i < 1000; ++i) {
    if (i % 100 >= 94) continue;
    const FairedPose p = pose_at(0.01 * i);
    Sample s;
    s.time = p.time;
    s.orientation = p.orientation;
    s.position = p.position;
    s.flags = kHasPosition;
    input.push_back(s);
  }
  std::size_t made = 0;
  for (auto _ : state) {
    GapBridge bridge(o);
    std::vector<Sample> out(bridge.max_outputs());
    made = 0;
    for (const Sample& s : input) made += bridge.push(s, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * input.size()));
  state.counters["samples_out"] = static_cast<double>(made);
}
BENCHMARK(BM_BridgeA100HzStreamWithDropouts)->Arg(0)->Arg(1)->ArgName("matrix_lerp")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
