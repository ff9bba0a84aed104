// BNO08x UART-RVC decoder: the datasheet's example frame, conventions, encode/decode round trips,
// chunking, resynchronisation, counters, index unwrapping, and 10 MB of random bytes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/bno08x_rvc_decoder.hpp"
#include "posefair/drivers/checksums.hpp"

namespace posefair::drivers::bno08x_rvc_decoder_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::size_t kFrame = kBno08xRvcFrameSize;

// BNO080 Datasheet 1000-3927 (Hillcrest Laboratories, October 2017), section 1.3.5.2: "An example
// complete message and checksum calculation is as follows: Message: 0xAA AA DE 01 00 92 FF 25 08
// 8D FE EC FF D1 03 00 00 00 E7", with Index = 222, Yaw = 0.01°, Pitch = -1.10°, Roll = 20.85°,
// X-acceleration = -371 mg (and, from the bytes, Y = -20 mg, Z = 977 mg).
const Bytes kDatasheetExample = {0xAA, 0xAA, 0xDE, 0x01, 0x00, 0x92, 0xFF, 0x25, 0x08, 0x8D,
                                 0xFE, 0xEC, 0xFF, 0xD1, 0x03, 0x00, 0x00, 0x00, 0xE7};

template <std::size_t N>
void append(Bytes& out, const std::array<std::uint8_t, N>& frame) {
  out.insert(out.end(), frame.begin(), frame.end());
}

std::unique_ptr<Decoder> make() { return make_bno08x_rvc_decoder(OptionMap{}); }

Decoded decode(const Bytes& stream) { return decode_chunks(make(), stream); }

void expect_consistent(const DecoderCounters& c) {
  EXPECT_EQ(c.frames, c.samples + c.malformed);
  EXPECT_EQ(c.ignored_frames, 0u);
  EXPECT_LE(c.skipped_bytes + kFrame * c.frames, c.bytes);
  EXPECT_GT(c.skipped_bytes + kFrame * c.frames + kFrame, c.bytes);
}

// 100 Hz of smooth synthetic motion; with garbage: junk bytes now and then, broken checksums, and
// a text banner like the one the module prints after reset.
Bytes motion_stream(std::mt19937_64& rng, int frames, bool garbage) {
  Bytes s;
  if (garbage) {
    const std::string banner = "%Hillcrest Labs 10003608\r\n%SW Ver 3.2.x\r\n";
    s.insert(s.end(), banner.begin(), banner.end());
  }
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < frames; ++k) {
    const double t = 0.01 * k;
    auto f = encode_bno08x_rvc(static_cast<std::uint8_t>(k + 200), 179.0 * std::sin(0.7 * t), 80.0 * std::sin(1.3 * t),
                               170.0 * std::cos(0.9 * t), 100.0 * std::sin(t), -50.0, 1000.0 - 10.0 * k);
    if (garbage && k % 7 == 3) f[9] ^= 0x20;  // broken checksum
    append(s, f);
    if (garbage && k % 5 == 1)
      for (int g = byte(rng) % 40; g > 0; --g) s.push_back(static_cast<std::uint8_t>(g % 3 ? byte(rng) : 0xAA));
  }
  return s;
}

TEST(Bno08xRvcDecoder, ProtocolName) { EXPECT_EQ(make()->protocol(), "bno08x-rvc"); }

TEST(Bno08xRvcDecoder, DatasheetExample) {
  const Decoded r = decode(kDatasheetExample);
  ASSERT_EQ(r.samples.size(), 1u);
  const DecodedSample& s = r.samples[0];
  EXPECT_TRUE(s.has_frame_counter);
  EXPECT_EQ(s.frame_counter, 222u);
  EXPECT_EQ(s.flags, kHasAccel);  // no device time, no position; the acceleration, in m/s²
  EXPECT_NEAR((s.accel - Vec3(-371, -20, 977) * 9.80665e-3).norm(), 0, 1e-12);
  EXPECT_LT(so3::rotation_angle(s.orientation, zyx(0.01, -1.10, 20.85)), 1e-12);
  DecoderCounters want;
  want.bytes = kFrame;
  want.frames = 1;
  want.samples = 1;
  EXPECT_EQ(r.counters, want);
  // The checksum covers the 16 bytes after the header, and the encoder writes the same frame.
  EXPECT_EQ(checksum::sum8({kDatasheetExample.data() + 2, 16}), 0xE7);
  const auto enc = encode_bno08x_rvc(0xDE, 0.01, -1.10, 20.85, -371, -20, 977);
  EXPECT_TRUE(std::equal(enc.begin(), enc.end(), kDatasheetExample.begin()));
}

// The datasheet's example with the three bytes after the accelerations set as a BNO086 would
// (motion intent 3, motion request 1, reserved 0): they are summed too, 0xE7 + 3 + 1 = 0xEB.
// Built by hand; every other test frame has these bytes zero, where a checksum over only 13
// bytes after the header would pass as well.
TEST(Bno08xRvcDecoder, ChecksumCoversTheBytesAfterTheAccelerations) {
  const Bytes f = {0xAA, 0xAA, 0xDE, 0x01, 0x00, 0x92, 0xFF, 0x25, 0x08, 0x8D,
                   0xFE, 0xEC, 0xFF, 0xD1, 0x03, 0x03, 0x01, 0x00, 0xEB};
  const Decoded r = decode(f);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_LT(so3::rotation_angle(r.samples[0].orientation, zyx(0.01, -1.10, 20.85)), 1e-12);
  const auto enc = encode_bno08x_rvc(0xDE, 0.01, -1.10, 20.85, -371, -20, 977, {3, 1, 0});
  EXPECT_TRUE(std::equal(enc.begin(), enc.end(), f.begin()));
  Bytes g = f;
  g[18] = 0xE7;  // the sum without them
  EXPECT_EQ(decode(g).counters.bad_checksum, 1u);
}

TEST(Bno08xRvcDecoder, RoundTripWithinQuantisation) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> half_turn(-180.0, 180.0), quarter_turn(-90.0, 90.0);
  // Each angle is off by at most 0.005°; three of them add up at most.
  const double bound = 3.0 * 0.005 * kDeg * 1.001;
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double yaw = half_turn(rng), pitch = quarter_turn(rng), roll = half_turn(rng);
    const auto f = encode_bno08x_rvc(static_cast<std::uint8_t>(i), yaw, pitch, roll);
    const Decoded r = decode(Bytes(f.begin(), f.end()));
    ASSERT_EQ(r.samples.size(), 1u);
    const double err = so3::rotation_angle(r.samples[0].orientation, zyx(yaw, pitch, roll));
    worst = std::max(worst, err);
    ASSERT_LE(err, bound) << yaw << " " << pitch << " " << roll;
    ASSERT_NEAR(r.samples[0].orientation.norm(), 1.0, 1e-14);
  }
  EXPECT_GT(worst, 0.1 * bound);
}

TEST(Bno08xRvcDecoder, AngleConventions) {
  const auto rotated = [](double yaw, double pitch, double roll, const Vec3& v) {
    const auto f = encode_bno08x_rvc(0, yaw, pitch, roll);
    const Decoded r = decode(Bytes(f.begin(), f.end()));
    return Vec3(r.samples.at(0).orientation * v);
  };
  const double tol = 1e-12;
  EXPECT_LT((rotated(90, 0, 0, Vec3::UnitX()) - Vec3::UnitY()).norm(), tol);   // yaw about Z
  EXPECT_LT((rotated(0, 90, 0, Vec3::UnitX()) + Vec3::UnitZ()).norm(), tol);   // pitch about Y
  EXPECT_LT((rotated(0, 0, 90, Vec3::UnitY()) - Vec3::UnitZ()).norm(), tol);   // roll about X
  // "applied in the order yaw, pitch then roll" (intrinsic): Rz(90) Ry(90) z = y (not x),
  // Rz(90) Rx(90) y = z (not -x), Ry(90) Rx(90) y = x (not z).
  EXPECT_LT((rotated(90, 90, 0, Vec3::UnitZ()) - Vec3::UnitY()).norm(), tol);
  EXPECT_LT((rotated(90, 0, 90, Vec3::UnitY()) - Vec3::UnitZ()).norm(), tol);
  EXPECT_LT((rotated(0, 90, 90, Vec3::UnitY()) - Vec3::UnitX()).norm(), tol);
}

TEST(Bno08xRvcDecoder, IndexRolloverIsUnwrapped) {
  Bytes s;
  for (int i = 250; i < 262; ++i) append(s, encode_bno08x_rvc(static_cast<std::uint8_t>(i), 0, 0, 0));
  append(s, encode_bno08x_rvc(9, 0, 0, 0));     // 261 -> 265: three frames lost
  append(s, encode_bno08x_rvc(9, 0, 0, 0));     // repeated: stays
  append(s, encode_bno08x_rvc(8, 0, 0, 0));     // one back: read as 255 forward
  append(s, encode_bno08x_rvc(10, 200, 0, 0));  // malformed, still counted: 520 + 2
  append(s, encode_bno08x_rvc(11, 0, 0, 0));
  const Decoded r = decode(s);
  std::vector<std::uint64_t> want;
  for (std::uint64_t i = 250; i < 262; ++i) want.push_back(i);
  want.insert(want.end(), {265, 265, 520, 523});
  ASSERT_EQ(r.samples.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_TRUE(r.samples[i].has_frame_counter);
    EXPECT_EQ(r.samples[i].frame_counter, want[i]) << i;
  }
  EXPECT_EQ(r.counters.malformed, 1u);

  // Across many wraps, and reset() starting over from the raw index.
  auto d = make();
  Collector sink;
  for (int i = 0; i < 1000; ++i) d->feed(encode_bno08x_rvc(static_cast<std::uint8_t>(i + 7), 0, 0, 0), sink);
  ASSERT_EQ(sink.samples.size(), 1000u);
  for (std::size_t i = 0; i < sink.samples.size(); ++i) ASSERT_EQ(sink.samples[i].frame_counter, i + 7);
  d->reset();
  d->feed(encode_bno08x_rvc(3, 0, 0, 0), sink);
  EXPECT_EQ(sink.samples.back().frame_counter, 3u);
}

TEST(Bno08xRvcDecoder, AnySplitGivesTheSameSamplesAndCounters) {
  std::mt19937_64 rng(3);
  const Bytes stream = motion_stream(rng, 60, true);
  const Decoded whole = decode(stream);
  ASSERT_GT(whole.samples.size(), 45u);
  ASSERT_GT(whole.counters.bad_checksum, 0u);
  ASSERT_GT(whole.counters.resyncs, 1u);
  expect_every_split_same(make, stream, whole);
  expect_byte_by_byte_same(make, stream, whole);
  expect_random_chunkings_same(make, stream, whole, rng, 300, {60, 20});  // empty chunks too
  expect_consistent(whole.counters);
}

TEST(Bno08xRvcDecoder, CleanStreamCounters) {
  std::mt19937_64 rng(4);
  const Bytes stream = motion_stream(rng, 500, false);
  const Decoded r = decode(stream);
  DecoderCounters want;
  want.bytes = stream.size();
  want.frames = 500;
  want.samples = 500;
  EXPECT_EQ(r.counters, want);
  for (std::size_t i = 0; i < r.samples.size(); ++i) EXPECT_EQ(r.samples[i].frame_counter, 200 + i);
}

// Garbage before, between and inside frames, a broken frame full of 0xAA, and a trailing partial
// frame; every counter derived by hand.
TEST(Bno08xRvcDecoder, ResynchronisationCountedExactly) {
  const auto f1 = encode_bno08x_rvc(1, 10, 20, 30);
  // Index 0xAA and x acceleration 0xAAAA (-21846 mg): "AA AA" at offsets 1-2 and 9-10.
  auto f2 = encode_bno08x_rvc(0xAA, 10, 20, 30, -21846, 5, 6);
  f2[18] = static_cast<std::uint8_t>(f2[18] + 1);  // broken
  const auto f3 = encode_bno08x_rvc(0xAA, -10, -20, -30, -21846, 5, 6);  // the same kind, intact
  const auto f4 = encode_bno08x_rvc(4, 40, 0, 0);
  Bytes s = {0x01, 0xAA, 0x02, 0xAA, 0x03};  // G1: lone 0xAA bytes: 5 bytes skipped
  append(s, f1);                             // at 5
  s.insert(s.end(), {0xAA, 0xAA, 0xAA});     // G2 at 24: three header-like bytes: skipped
  append(s, f2);                             // at 27: 19 bytes skipped
  append(s, f3);                             // at 46
  s.insert(s.end(), f4.begin(), f4.begin() + 5);  // held until the rest arrives

  // Preconditions of the hand count: in the skipped bytes, "AA AA" starts exactly at G2's three
  // bytes and at f2's offsets 0, 1 (header, index) and 9 (the acceleration), and each of these
  // false starts fails its checksum.
  std::vector<std::size_t> starts;
  for (std::size_t at = 0; at < 46; ++at) {
    if (at >= 5 && at < 24) continue;  // f1
    if (s[at] == 0xAA && s[at + 1] == 0xAA) {
      starts.push_back(at);
      ASSERT_NE(checksum::sum8({s.data() + at + 2, 16}), s[at + 18]) << at;
    }
  }
  ASSERT_EQ(starts, (std::vector<std::size_t>{24, 25, 26, 27, 28, 36}));

  auto d = make();
  Collector sink;
  d->feed(s, sink);
  DecoderCounters want;
  want.bytes = s.size();
  want.frames = 2;
  want.samples = 2;
  want.bad_checksum = 3 + 3;  // G2's three false starts; f2, and "AA AA" at its offsets 1 and 9
  want.resyncs = 2;           // G1; G2 and f2 are one run
  want.skipped_bytes = 5 + 3 + 19;
  EXPECT_EQ(d->counters(), want);
  ASSERT_EQ(sink.samples.size(), 2u);
  EXPECT_EQ(sink.samples[0].frame_counter, 1u);
  EXPECT_EQ(sink.samples[1].frame_counter, 0xAAu);
  EXPECT_LT(so3::rotation_angle(sink.samples[1].orientation, zyx(-10, -20, -30)), 1e-3);

  d->feed(std::span<const std::uint8_t>(f4.data() + 5, f4.size() - 5), sink);
  want.bytes += f4.size() - 5;
  want.frames = 3;
  want.samples = 3;
  EXPECT_EQ(d->counters(), want);
  ASSERT_EQ(sink.samples.size(), 3u);
  EXPECT_EQ(sink.samples[2].frame_counter, 0xAAu + 90u);  // index 0xAA -> 4 is 90 steps on
  EXPECT_LT(so3::rotation_angle(sink.samples[2].orientation, zyx(40, 0, 0)), 1e-3);
}

TEST(Bno08xRvcDecoder, ByteInsertedInsideAFrameLosesOnlyThatFrame) {
  Bytes s;
  append(s, encode_bno08x_rvc(1, 10, 0, 0));
  append(s, encode_bno08x_rvc(2, 20, 0, 0));
  s.insert(s.begin() + 19 + 8, 0x77);
  append(s, encode_bno08x_rvc(3, 30, 0, 0));
  const Decoded r = decode(s);
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.samples[1].frame_counter, 3u);
  EXPECT_EQ(r.counters.bad_checksum, 1u);
  EXPECT_EQ(r.counters.resyncs, 1u);
  EXPECT_EQ(r.counters.skipped_bytes, 20u);
}

TEST(Bno08xRvcDecoder, OutOfRangeAnglesAreMalformed) {
  Bytes s;
  append(s, encode_bno08x_rvc(0, 180.0, 90.0, -180.0));  // the limits: fine
  append(s, encode_bno08x_rvc(1, 180.01, 0, 0));
  append(s, encode_bno08x_rvc(2, 0, -90.01, 0));
  append(s, encode_bno08x_rvc(3, 0, 0, 200.0));
  append(s, encode_bno08x_rvc(4, 0, 0, 0, 0, 0, 0, {1, 1, 0xFF}));  // the last three bytes are not checked
  const Decoded r = decode(s);
  EXPECT_EQ(r.counters.frames, 5u);
  EXPECT_EQ(r.counters.malformed, 3u);
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.samples[1].frame_counter, 4u);
  expect_consistent(r.counters);
}

TEST(Bno08xRvcDecoder, ResetForgetsAPartialFrame) {
  const auto f = encode_bno08x_rvc(5, 10, 0, 0);
  auto d = make();
  Collector sink;
  d->feed(std::span<const std::uint8_t>(f.data(), 9), sink);
  d->reset();
  d->feed(std::span<const std::uint8_t>(f.data() + 9, 10), sink);
  EXPECT_TRUE(sink.samples.empty());
  EXPECT_EQ(d->counters().skipped_bytes, 10u);
  d->feed(f, sink);
  EXPECT_EQ(sink.samples.size(), 1u);
}

// 10 MB of random bytes: no crash, only unit quaternions, and about as many accepted frames and
// failed checksums as the frame rules predict. At each position a frame is accepted with
// probability (1/256)² (0xAA 0xAA) · 1/256 (checksum) = 2^-24, and a checksum is tried and fails
// with probability (1/256)² · 255/256. Both counts are close to Poisson.
TEST(Bno08xRvcDecoder, RandomBytes) {
  constexpr std::size_t kBytes = 10'000'000;
  std::mt19937_64 rng(20171001);
  const Bytes data = random_bytes(kBytes, rng);
  const Decoded r = decode_in_random_reads(make(), data, rng);
  const DecoderCounters& c = r.counters;
  EXPECT_EQ(c.bytes, kBytes);
  expect_consistent(c);
  expect_poisson_at_most(c.frames, kBytes / 16777216.0);
  expect_poisson_near(c.bad_checksum, kBytes / 65536.0 * (255.0 / 256.0));
  expect_unit_quaternions(r.samples);
  for (const auto& s : r.samples) ASSERT_TRUE(s.has_frame_counter);

  // Random bytes with valid frames spliced in every ~500 bytes: every one of them is found.
  Bytes mixed(data.begin(), data.begin() + 1'000'000);
  std::vector<std::size_t> planted;
  for (std::size_t at = 250, k = 0; at + kFrame < mixed.size(); at += 500, ++k) {
    const auto f = encode_bno08x_rvc(static_cast<std::uint8_t>(k), 1.0 * (k % 300) - 150, 0, 0);
    std::copy(f.begin(), f.end(), mixed.begin() + static_cast<std::ptrdiff_t>(at));
    planted.push_back(k);
  }
  const Decoded m = decode(mixed);
  std::size_t found = 0;  // the planted frames, in order, among the samples
  for (const auto& s : m.samples)
    if (found < planted.size() && so3::rotation_angle(s.orientation, zyx(1.0 * (found % 300) - 150, 0, 0)) < 1e-9)
      ++found;
  EXPECT_EQ(found, planted.size());
  EXPECT_LE(m.counters.samples, planted.size() + 5);
}

}  // namespace
}  // namespace posefair::drivers::bno08x_rvc_decoder_test
