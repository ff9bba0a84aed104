// VectorNav ASCII decoder throughput: MB/s decoding a realistic stream, i.e. sentences of a
// random smooth motion (VNQMR with the XOR checksum or the CRC-16, VNYMR with XOR) in which
// about 1% of the bytes are replaced by random ones, fed in reads of 64 or 4096 bytes.
// Goal: >= 50 MB/s on one core. Run: build/tests/bench/vectornav_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "posefair/core/so3.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"

namespace posefair::drivers {
namespace {

enum class Kind { kQmrXor, kQmrCrc, kYmrXor };

struct Counter final : DecodedSink {
  std::uint64_t n = 0;
  void on_sample(const DecodedSample&) override { ++n; }
};

// 20000 sentences of a smooth random motion (angular velocity a random walk), then ~1% of the
// bytes replaced by random values.
std::vector<std::uint8_t> stream(Kind kind) {
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> n01;
  Quat q = Quat::Identity();
  Vec3 omega = Vec3::Zero();
  std::string s;
  for (int k = 0; k < 20000; ++k) {
    omega = 0.98 * omega + 0.05 * Vec3(n01(rng), n01(rng), n01(rng));
    q = (q * so3::from_rotation_vector(omega * 0.01)).normalized();
    if (kind == Kind::kYmrXor) {
      // Tait-Bryan Z-Y-X angles of R = Rz(yaw) Ry(pitch) Rx(roll).
      const Eigen::Matrix3d r = q.toRotationMatrix();
      const double deg = 180.0 / std::numbers::pi;
      s += encode_vectornav_vnymr(std::atan2(r(1, 0), r(0, 0)) * deg, -std::asin(std::clamp(r(2, 0), -1.0, 1.0)) * deg,
                                  std::atan2(r(2, 1), r(2, 2)) * deg, false);
    } else {
      s += encode_vectornav_vnqmr(q, kind == Kind::kQmrCrc);
    }
  }
  std::vector<std::uint8_t> bytes(s.begin(), s.end());
  std::bernoulli_distribution corrupt(0.01);
  for (auto& b : bytes)
    if (corrupt(rng)) b = static_cast<std::uint8_t>(rng());
  return bytes;
}

void BM_VectorNav(benchmark::State& state, Kind kind) {
  const std::vector<std::uint8_t> data = stream(kind);
  const auto chunk = static_cast<std::size_t>(state.range(0));
  auto decoder = make_vectornav_decoder({});
  Counter sink;
  for (auto _ : state) {
    for (std::size_t at = 0; at < data.size(); at += chunk)
      decoder->feed({data.data() + at, std::min(chunk, data.size() - at)}, sink);
    benchmark::DoNotOptimize(sink.n);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(data.size()));
  state.counters["samples_per_pass"] = static_cast<double>(sink.n) / static_cast<double>(state.iterations());
  state.counters["stream_kB"] = static_cast<double>(data.size()) / 1000.0;
}

BENCHMARK_CAPTURE(BM_VectorNav, vnqmr_xor, Kind::kQmrXor)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VectorNav, vnqmr_crc16, Kind::kQmrCrc)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VectorNav, vnymr_xor, Kind::kYmrXor)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
