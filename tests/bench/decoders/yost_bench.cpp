// Yost 3-Space decoder throughput: MB/s decoding a realistic stream, i.e. packets (default
// header 0x4F, 24 bytes each) of a random smooth motion in which about 1% of the bytes are
// replaced by random ones, fed in reads of 64 or 4096 bytes. Also a stream of random bytes
// (all resync). Goal: >= 50 MB/s on one core. Run: build/tests/bench/yost_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "decoder_bench.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/yost_decoder.hpp"

namespace posefair::drivers {
namespace {

// 100000 packets at 1 kHz of a smooth random motion, then ~1% of the bytes replaced.
std::vector<std::uint8_t> stream(bool random_only) {
  std::mt19937_64 rng(12345);
  std::vector<std::uint8_t> bytes;
  if (random_only) {
    bytes.resize(2'400'000);
    for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
    return bytes;
  }
  std::normal_distribution<double> n01;
  Quat q = Quat::Identity();
  Vec3 omega = Vec3::Zero();
  for (std::uint32_t k = 0; k < 100000; ++k) {
    omega = 0.98 * omega + 0.05 * Vec3(n01(rng), n01(rng), n01(rng));
    q = (q * so3::from_rotation_vector(omega * 0.01)).normalized();
    const std::vector<std::uint8_t> p = encode_yost_quaternion_packet(q, 0xFFF00000u + 1000u * k);
    bytes.insert(bytes.end(), p.begin(), p.end());
  }
  bench::corrupt(bytes, 0.01, rng);
  return bytes;
}

void BM_Yost(benchmark::State& state, bool random_only) {
  const std::vector<std::uint8_t> data = stream(random_only);
  auto decoder = make_yost_decoder({});
  bench::decode_in_reads(state, *decoder, data, static_cast<std::size_t>(state.range(0)));
}

BENCHMARK_CAPTURE(BM_Yost, packets_1pct_corrupt, false)->Arg(64)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Yost, random_bytes, true)->Arg(4096)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
