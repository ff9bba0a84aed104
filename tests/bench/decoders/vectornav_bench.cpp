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

#include "decoder_bench.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"

namespace posefair::drivers {
namespace {

enum class Kind { kQmrXor, kQmrCrc, kYmrXor };

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
  bench::corrupt(bytes, 0.01, rng);
  return bytes;
}

void BM_VectorNav(benchmark::State& state, Kind kind) {
  const std::vector<std::uint8_t> data = stream(kind);
  auto decoder = make_vectornav_decoder({});
  bench::decode_in_reads(state, *decoder, data, static_cast<std::size_t>(state.range(0)));
}

BENCHMARK_CAPTURE(BM_VectorNav, vnqmr_xor, Kind::kQmrXor)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VectorNav, vnqmr_crc16, Kind::kQmrCrc)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_VectorNav, vnymr_xor, Kind::kYmrXor)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
