// WitMotion decoder throughput (MB/s of input) on one core, over a realistic ~4 MB stream: per
// output cycle the packets 0x50 time, 0x51 accel, 0x52 gyro, 0x53 angles, 0x54 mag and 0x59
// quaternion from a smooth synthetic motion, then 1% of the bytes replaced by random ones.
// - Mixed: that stream (one sample per cycle, from 0x59; 0x53 ignored).
// - AnglesOnly: the same without 0x59 (every 0x53 converted: three sin/cos pairs per sample).
// - Clean: the mixed stream without corruption.
// The argument is the size of each feed() call (a serial read returns tens to thousands of bytes).
// Run: build/tests/bench/witmotion_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "decoder_bench.hpp"
#include "posefair/drivers/witmotion_decoder.hpp"

namespace posefair::drivers {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr double kDeg = std::numbers::pi / 180.0;

template <std::size_t N>
void append(Bytes& out, const std::array<std::uint8_t, N>& f) {
  out.insert(out.end(), f.begin(), f.end());
}

Bytes make_stream(bool with_quaternion, double corrupt_fraction) {
  Bytes s;
  const int cycles = 4'000'000 / 66;
  for (int k = 0; k < cycles; ++k) {
    const double t = 0.005 * k;
    const double yaw = 170.0 * std::sin(0.7 * t), pitch = 60.0 * std::sin(1.3 * t), roll = 150.0 * std::cos(0.9 * t);
    const int ms = (k * 5) % 1000, total_s = k / 200;
    append(s, encode_witmotion_time(25, 1, 1, (total_s / 3600) % 24, (total_s / 60) % 60, total_s % 60, ms));
    append(s, encode_witmotion_frame(0x51, {0x10, 0x00, 0xF0, 0xFF, 0x00, 0x08, 0x10, 0x0A}));
    append(s, encode_witmotion_frame(0x52, {0x03, 0x00, 0xFD, 0xFF, 0x01, 0x00, 0x10, 0x0A}));
    append(s, encode_witmotion_angles(roll, pitch, yaw, 0x1234));
    append(s, encode_witmotion_frame(0x54, {0x2C, 0x01, 0x38, 0xFF, 0x64, 0x00, 0x10, 0x0A}));
    if (with_quaternion) {
      const Quat q = Quat(Eigen::AngleAxisd(yaw * kDeg, Vec3::UnitZ())) *
                     Quat(Eigen::AngleAxisd(pitch * kDeg, Vec3::UnitY())) *
                     Quat(Eigen::AngleAxisd(roll * kDeg, Vec3::UnitX()));
      append(s, encode_witmotion_quaternion(q));
    }
  }
  std::mt19937_64 rng(1);
  bench::corrupt(s, corrupt_fraction, rng);
  return s;
}

void run(benchmark::State& state, const Bytes& stream) {
  auto decoder = make_witmotion_decoder(OptionMap{});
  bench::decode_in_reads(state, *decoder, stream, static_cast<std::size_t>(state.range(0)));
}

void BM_Mixed(benchmark::State& state) {
  static const Bytes stream = make_stream(true, 0.01);
  run(state, stream);
}
void BM_AnglesOnly(benchmark::State& state) {
  static const Bytes stream = make_stream(false, 0.01);
  run(state, stream);
}
void BM_Clean(benchmark::State& state) {
  static const Bytes stream = make_stream(true, 0.0);
  run(state, stream);
}
BENCHMARK(BM_Mixed)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AnglesOnly)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Clean)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
