// Cost per evaluated sample of the geometric splines (docs/splines.md): one segment
// evaluation at a time inside a 100-knot spline, for each manifold and k = 1, 2, 3; the
// pose-level spline (S^3 or SO(3) orientation + R^3 position); and the live window's push.
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>

#include "posefair/core/euclidean_geometric_spline.hpp"
#include "posefair/core/pose_spline.hpp"
#include "posefair/core/pose_spline_window.hpp"
#include "posefair/core/so3_geometric_spline.hpp"
#include "posefair/core/sphere_geometric_spline.hpp"

namespace gs = posefair::geometric_splines;
using posefair::Quat;
using posefair::Vec3;

namespace {

constexpr int kKnots = 100;
constexpr int kQueries = 1024;

posefair::PoseSequence motion() {
  posefair::PoseSequence s;
  for (int i = 0; i < kKnots; ++i) {
    const double t = 0.01 * i;
    s.time.push_back(t);
    s.orientation.push_back(posefair::so3::exp(Vec3(std::sin(3 * t), std::cos(2 * t), t)));
    s.position.push_back(Vec3(std::sin(t), t * t, 1.0));
  }
  return s;
}

std::vector<double> query_times() {
  std::vector<double> t(kQueries);
  for (int i = 0; i < kQueries; ++i) t[i] = 0.99 * (i + 0.5) / kQueries;
  return t;
}

void BM_R3(benchmark::State& state) {
  const auto m = motion();
  std::vector<gs::EuclideanKnot<3>> knots;
  for (int i = 0; i < kKnots; ++i) knots.push_back({m.time[i], {m.position[i], Vec3(1.0, 0.5, 0.0)}});
  const gs::EuclideanGeometricSpline<3> s(knots, static_cast<int>(state.range(0)));
  const auto times = query_times();
  for (auto _ : state)
    for (double t : times) benchmark::DoNotOptimize(s.evaluate(t));
  state.SetItemsProcessed(state.iterations() * kQueries);
}

void BM_S3(benchmark::State& state) {
  const gs::PoseSpline ps(motion(), {});
  std::vector<double> times;
  std::vector<gs::SpherePoint<4>> points, velocities;
  for (const auto& k : ps.knots()) {
    times.push_back(k.time);
    points.push_back(k.orientation.coeffs());
    velocities.push_back(0.5 * (Quat(0.0, k.angular_velocity.x(), k.angular_velocity.y(), k.angular_velocity.z()) *
                                k.orientation).coeffs());
  }
  const gs::SphereGeometricSpline<4> s(times, points, velocities, static_cast<int>(state.range(0)));
  const auto query = query_times();
  for (auto _ : state)
    for (double t : query) benchmark::DoNotOptimize(s.evaluate(t));
  state.SetItemsProcessed(state.iterations() * kQueries);
}

void BM_SO3(benchmark::State& state) {
  const gs::PoseSpline ps(motion(), {});
  std::vector<double> times;
  std::vector<gs::Rotation> rotations;
  std::vector<Vec3> omegas;
  for (const auto& k : ps.knots()) {
    times.push_back(k.time);
    rotations.push_back(k.orientation.toRotationMatrix());
    omegas.push_back(k.angular_velocity);
  }
  const gs::So3GeometricSpline s(times, rotations, omegas, static_cast<int>(state.range(0)));
  const auto query = query_times();
  for (auto _ : state)
    for (double t : query) benchmark::DoNotOptimize(s.evaluate(t));
  state.SetItemsProcessed(state.iterations() * kQueries);
}

void BM_Pose(benchmark::State& state) {
  gs::PoseSplineOptions o;
  o.order = static_cast<int>(state.range(0));
  o.manifold = state.range(1) ? gs::OrientationManifold::LieGroup : gs::OrientationManifold::Sphere;
  const gs::PoseSpline s(motion(), o);
  const auto query = query_times();
  for (auto _ : state)
    for (double t : query) benchmark::DoNotOptimize(s.evaluate(t));
  state.SetItemsProcessed(state.iterations() * kQueries);
}

// Live window: push one 100 Hz sample, then evaluate the 250 Hz outputs that became ready.
void BM_WindowPushAndEvaluate(benchmark::State& state) {
  const auto m = motion();
  gs::PoseSplineWindow w(16, {}, true);
  std::size_t i = 0;
  double next_output = 0.0;
  gs::SplinePose out;
  for (auto _ : state) {
    const double t = 0.01 * static_cast<double>(i);
    w.push(t, m.orientation[i % kKnots], m.position[i % kKnots]);
    ++i;
    const auto range = w.ready_range();
    while (range && next_output <= range->second) {
      if (next_output >= range->first) benchmark::DoNotOptimize(w.evaluate(next_output, out));
      next_output += 0.004;
    }
  }
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

BENCHMARK(BM_R3)->DenseRange(1, 3);
BENCHMARK(BM_S3)->DenseRange(1, 3);
BENCHMARK(BM_SO3)->DenseRange(1, 3);
BENCHMARK(BM_Pose)->ArgsProduct({{1, 2, 3}, {0, 1}});
BENCHMARK(BM_WindowPushAndEvaluate);
BENCHMARK_MAIN();
