// exp, log, sqrt and one lerp of 4x4 transforms: the paper's iterations (posefair core) against
// Eigen's MatrixFunctions, on the same matrices in the same run.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>

#include "posefair/core/eigen_matrix_functions.hpp"
#include "posefair/core/linear_combination.hpp"
#include "posefair/core/matrix_interpolation_study.hpp"

namespace {

using posefair::Mat4;

// Section 4.2 transforms that have a principal logarithm (the others are refused up front).
const std::vector<Mat4>& test_matrices() {
  static const std::vector<Mat4> m = [] {
    std::mt19937_64 rng(9);
    std::vector<Mat4> out;
    while (out.size() < 64) {
      const Mat4 a = posefair::random_test_transform(rng);
      if (posefair::matrix_log(a)) out.push_back(a);
    }
    return out;
  }();
  return m;
}

const std::vector<Mat4>& test_logs() {
  static const std::vector<Mat4> l = [] {
    std::vector<Mat4> out;
    for (const Mat4& a : test_matrices()) out.push_back(posefair::eigen_matrix_log(a));
    return out;
  }();
  return l;
}

template <class F>
void over(benchmark::State& state, const std::vector<Mat4>& in, F f) {
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f(in[i]));
    i = (i + 1) % in.size();
  }
}

void BM_Exp_Paper(benchmark::State& s) { over(s, test_logs(), [](const Mat4& a) { return posefair::matrix_exp(a).value(); }); }
void BM_Exp_Eigen(benchmark::State& s) { over(s, test_logs(), [](const Mat4& a) { return posefair::eigen_matrix_exp(a); }); }
void BM_Sqrt_Paper(benchmark::State& s) {
  over(s, test_matrices(), [](const Mat4& a) { return posefair::matrix_sqrt(a).ok(); });
}
void BM_Sqrt_Eigen(benchmark::State& s) { over(s, test_matrices(), [](const Mat4& a) { return posefair::eigen_matrix_sqrt(a); }); }
void BM_Log_Paper(benchmark::State& s) { over(s, test_matrices(), [](const Mat4& a) { return posefair::matrix_log(a).ok(); }); }
void BM_Log_Eigen(benchmark::State& s) { over(s, test_matrices(), [](const Mat4& a) { return posefair::eigen_matrix_log(a); }); }

// One lerp about the first key (eq. 7): log(B A^-1), then exp(t L) A.
const Mat4 kA = [] {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() *
                            Eigen::Vector3d(1.0, 1.5, 0.7).asDiagonal();
  m.topRightCorner<3, 1>() = Eigen::Vector3d(1, 2, 3);
  return m;
}();
const Mat4 kB = [] {
  Mat4 m = kA;
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.6, Eigen::Vector3d(0, 1, 0)).toRotationMatrix() * m.topLeftCorner<3, 3>();
  m.topRightCorner<3, 1>() += Eigen::Vector3d(0.5, -1, 2);
  return m;
}();

void BM_Lerp_Paper(benchmark::State& s) {
  for (auto _ : s) benchmark::DoNotOptimize(posefair::lerp(kA, kB, 0.37).value());
}
void BM_Lerp_Eigen(benchmark::State& s) {
  for (auto _ : s) benchmark::DoNotOptimize(Mat4(posefair::eigen_matrix_exp(0.37 * posefair::eigen_matrix_log(kB * kA.inverse())) * kA));
}
// The daemon's case: keys prepared once, one evaluation per output.
void BM_PreparedLerpAt_Paper(benchmark::State& s) {
  const auto p = posefair::PreparedLerp::make(kA, kB).value();
  double t = 0.0;
  for (auto _ : s) {
    benchmark::DoNotOptimize(p.at(t).value());
    t = t > 1.0 ? 0.0 : t + 0.01;
  }
}

BENCHMARK(BM_Exp_Paper);
BENCHMARK(BM_Exp_Eigen);
BENCHMARK(BM_Sqrt_Paper);
BENCHMARK(BM_Sqrt_Eigen);
BENCHMARK(BM_Log_Paper);
BENCHMARK(BM_Log_Eigen);
BENCHMARK(BM_Lerp_Paper);
BENCHMARK(BM_Lerp_Eigen);
BENCHMARK(BM_PreparedLerpAt_Paper);

}  // namespace

BENCHMARK_MAIN();
