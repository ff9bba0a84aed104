// Decoding throughput of posefair's serial protocol decoder
// (drivers/src/posefair_serial_decoder.cpp): MB/s of a realistic stream along smooth random
// motion with positions (core/synthetic_motion.hpp): text sentences only (7 decimals, as a
// microcontroller prints them), binary frames only, or the two alternating; about 1% of the
// bytes replaced by random ones. Fed in pieces of 64 bytes (what a serial read typically
// returns) or 4096. Goal: at least 50 MB/s on one core.
// Run: build/tests/bench/posefair_serial_bench
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "decoder_bench.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/drivers/checksums.hpp"
#include "posefair/drivers/posefair_serial_decoder.hpp"

namespace posefair::drivers {
namespace {

enum Form { kText = 0, kBinary = 1, kMixed = 2 };

// A sentence as a microcontroller prints it: 7 decimals (not the encoder's shortest
// round-trip form, which writes up to 17 digits).
std::string printed_sentence(std::uint32_t t, const Quat& q, const Vec3& p) {
  char body[160];
  std::snprintf(body, sizeof body, "PFQ,%u,%.7f,%.7f,%.7f,%.7f,%.7f,%.7f,%.7f", t, q.w(), q.x(), q.y(), q.z(), p.x(),
                p.y(), p.z());
  const std::string b = body;
  const std::uint8_t x = checksum::xor8({reinterpret_cast<const std::uint8_t*>(b.data()), b.size()});
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", x);
  return "$" + b + tail;
}

std::vector<std::uint8_t> make_stream(Form form) {
  SyntheticMotionSpec spec;
  spec.samples = 40000;
  spec.sample_rate_hz = 200.0;
  spec.cycles = 20.0;
  spec.rotation_noise = 0.01;
  spec.with_position = true;
  const SyntheticMotion motion = make_synthetic_motion(spec);
  std::vector<std::uint8_t> stream;
  for (std::size_t k = 0; k < motion.noisy.size(); ++k) {
    const Quat& q = motion.noisy.orientation[k];
    const Vec3 p = motion.noisy.position[k] / 1000.0;  // mm -> m
    const auto t = static_cast<std::uint32_t>(5000 * k);
    const bool binary = form == kBinary || (form == kMixed && k % 2 == 1);
    if (binary) {
      const std::vector<std::uint8_t> f = encode_posefair_frame(t, q, &p);
      stream.insert(stream.end(), f.begin(), f.end());
    } else {
      const std::string s = printed_sentence(t, q, p);
      stream.insert(stream.end(), s.begin(), s.end());
    }
  }
  std::mt19937_64 rng(1);
  bench::corrupt(stream, 0.01, rng);
  return stream;
}

void BM_PosefairSerialDecode(benchmark::State& state) {
  static const std::vector<std::uint8_t> streams[3] = {make_stream(kText), make_stream(kBinary), make_stream(kMixed)};
  const std::vector<std::uint8_t>& stream = streams[state.range(0)];
  auto decoder = make_posefair_serial_decoder();
  bench::decode_in_reads(state, *decoder, stream, static_cast<std::size_t>(state.range(1)));
  state.SetLabel(state.range(0) == kText ? "text" : state.range(0) == kBinary ? "binary" : "mixed");
}
BENCHMARK(BM_PosefairSerialDecode)->ArgsProduct({{kText, kBinary, kMixed}, {64, 4096}});

}  // namespace
}  // namespace posefair::drivers

BENCHMARK_MAIN();
