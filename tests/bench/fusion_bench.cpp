// Cost of one orientation estimator update (9D and 6D), on a synthetic 200 Hz recording that
// turns all the time: the goal is at least 1 M updates per second per core (docs/fusion.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "posefair/core/orientation_estimator.hpp"

namespace posefair {
namespace {

std::vector<Sample> recording() {
  std::vector<Sample> out;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  Quat q = Quat::Identity();
  const double dt = 0.005;
  for (int k = 0; k < 4096; ++k) {
    const double t = k * dt;
    const Vec3 w(std::sin(0.7 * t), 0.8 * std::cos(0.5 * t), 1.2 * std::sin(0.3 * t));
    q = (q * so3::from_rotation_vector(w * dt)).normalized();
    Sample s;
    s.time = t;
    s.gyro = w + Vec3(noise(rng), noise(rng), noise(rng));
    s.accel = q.conjugate() * Vec3(0, 0, 9.81) + Vec3(noise(rng), noise(rng), noise(rng));
    s.mag = q.conjugate() * Vec3(0, 20, -40) + Vec3(noise(rng), noise(rng), noise(rng));
    s.flags = kHasGyro | kHasAccel | kHasMag | kNoOrientation;
    out.push_back(s);
  }
  return out;
}

void BM_EstimatorUpdate(benchmark::State& state, const char* name, bool use_mag) {
  const std::vector<Sample> samples = recording();
  auto e = make_orientation_estimator(name, {{"magnetometer", use_mag}});
  std::size_t k = 0;
  for (auto _ : state) {
    e->update(samples[k], 0.005);
    benchmark::DoNotOptimize(e->orientation());
    if (++k == samples.size()) k = 0;
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_CAPTURE(BM_EstimatorUpdate, vqf_9d, "vqf", true);
BENCHMARK_CAPTURE(BM_EstimatorUpdate, vqf_6d, "vqf", false);
BENCHMARK_CAPTURE(BM_EstimatorUpdate, madgwick_9d, "madgwick", true);
BENCHMARK_CAPTURE(BM_EstimatorUpdate, mahony_9d, "mahony", true);

}  // namespace
}  // namespace posefair

BENCHMARK_MAIN();
