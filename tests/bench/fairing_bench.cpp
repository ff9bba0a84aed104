// Cost of Lee & Shin batch fairing: per sample per sweep for m = 2 and 3, orientation only and
// with positions, and the paper's case of 300 samples × 100 iterations with positions
// (reported as about 1 s on a 133 MHz SGI Indigo 2). Numbers go into docs/fairing.md.
#include <benchmark/benchmark.h>

#include <limits>

#include "posefair/core/fairing.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair {
namespace {

void BM_DampedSweeps(benchmark::State& state) {
  const int order = static_cast<int>(state.range(0));
  const bool with_position = state.range(1) != 0;
  const auto samples = static_cast<std::size_t>(state.range(2));
  SyntheticMotionSpec spec;
  spec.samples = samples;
  spec.with_position = with_position;
  const auto motion = make_synthetic_motion(spec);
  FairingParams params;
  params.order = order;
  params.max_iterations = 100;
  for (auto _ : state) {
    auto r = fair(motion.noisy, params);
    benchmark::DoNotOptimize(r.poses.orientation.data());
  }
  // One "item" = one sample in one sweep; items_per_second inverts to cost per sample per sweep.
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(samples) * params.max_iterations);
  state.SetLabel(std::string(with_position ? "orientation+position" : "orientation only") + ", m=" + std::to_string(order));
}

BENCHMARK(BM_DampedSweeps)
    ->ArgNames({"m", "pos", "n"})
    ->Args({2, 0, 1000})
    ->Args({3, 0, 1000})
    ->Args({2, 1, 1000})
    ->Args({3, 1, 1000})
    ->Unit(benchmark::kMillisecond);

// The paper's timing case: 300 samples with positions, 100 iterations, m = 3 (λ_t 0.5, λ_r 0.1).
void BM_PaperCase300x100(benchmark::State& state) {
  SyntheticMotionSpec spec;
  spec.samples = 300;
  const auto motion = make_synthetic_motion(spec);
  FairingParams params;
  params.order = 3;
  params.max_iterations = 100;
  for (auto _ : state) {
    auto r = fair(motion.noisy, params);
    benchmark::DoNotOptimize(r.poses.orientation.data());
  }
}
BENCHMARK(BM_PaperCase300x100)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair

BENCHMARK_MAIN();
