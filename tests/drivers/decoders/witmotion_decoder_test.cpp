// WitMotion decoder: documented-layout frames, conventions, encode/decode round trips, chunking,
// resynchronisation, counters, device time, and 10 MB of random bytes.
//
// Vendor examples: the WitMotion documents consulted (WT901 Datasheet v20-0702, WT901SDCL
// Datasheet v20-0605, WT901BLECL Datasheet v20-0707, docs.wit-motion.com HWT905-TTL protocol)
// give the packet layouts and formulas but no byte-exact 11-byte example packet (the only
// example bytes, "55 71 3A 00 68 01 ...", are a 20-byte Bluetooth register reply, another
// protocol). The frames in DocumentLayoutFrames are therefore written by hand from the layout,
// their checksums summed by hand, independently of the encoders.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/checksums.hpp"
#include "posefair/drivers/witmotion_decoder.hpp"

namespace posefair::drivers::witmotion_decoder_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;
constexpr double kDeg = std::numbers::pi / 180.0;

template <std::size_t N>
void append(Bytes& out, const std::array<std::uint8_t, N>& frame) {
  out.insert(out.end(), frame.begin(), frame.end());
}

std::unique_ptr<Decoder> make(const std::string& scalar = "first") {
  OptionMap o;
  o["witmotion_scalar"] = std::string(scalar);
  return make_witmotion_decoder(o);
}

Decoded decode(const Bytes& stream, const std::string& scalar = "first") { return decode_chunks(make(scalar), stream); }

// Every valid frame is a sample's orientation or one of its raw readings, ignored or malformed;
// every byte fed is skipped, in a frame, or still held (fewer than a frame).
void expect_consistent(const Decoded& r) {
  const DecoderCounters& c = r.counters;
  std::uint64_t used = 0;
  for (const auto& s : r.samples)
    used += ((s.flags & kNoOrientation) == 0) + std::popcount(s.flags & (kHasGyro | kHasAccel | kHasMag));
  EXPECT_EQ(c.frames, used + c.ignored_frames + c.malformed);
  EXPECT_LE(c.skipped_bytes + kWitMotionFrameSize * c.frames, c.bytes);
  EXPECT_GT(c.skipped_bytes + kWitMotionFrameSize * c.frames + kWitMotionFrameSize, c.bytes);
}

std::array<std::uint8_t, 11> accel_frame(std::uint8_t a = 0x12) {
  return encode_witmotion_frame(0x51, {a, 0x00, 0x34, 0x00, 0x00, 0x08, 0x10, 0x0A});
}

// A realistic output: per cycle time, accel, gyro, angles, mag, quaternion, from a smooth
// synthetic motion; garbage bytes now and then, a frame with a broken checksum, an unknown type.
Bytes motion_stream(std::mt19937_64& rng, int cycles, bool garbage) {
  Bytes s;
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < cycles; ++k) {
    const double t = 0.01 * k;
    const double yaw = 170.0 * std::sin(0.7 * t), pitch = 60.0 * std::sin(1.3 * t), roll = 150.0 * std::cos(0.9 * t);
    const int ms = (k * 10) % 1000, sec = (k / 100) % 60;
    append(s, encode_witmotion_time(24, 2, 29, 23, 59, sec, ms));
    append(s, accel_frame(static_cast<std::uint8_t>(k)));
    append(s, encode_witmotion_frame(0x52, {0x55, 0x55, 0x59, 0x55, 0x00, 0x00, 0x00, 0x00}));  // 0x55s in data
    append(s, encode_witmotion_angles(roll, pitch, yaw, 0x1234));
    append(s, encode_witmotion_frame(0x54, {1, 2, 3, 4, 5, 6, 7, 8}));
    auto q = encode_witmotion_quaternion(zyx(yaw, pitch, roll));
    if (garbage && k % 7 == 3) q[5] ^= 0x40;  // broken checksum
    append(s, q);
    if (garbage && k % 5 == 1)
      for (int g = byte(rng) % 23; g > 0; --g) s.push_back(static_cast<std::uint8_t>(byte(rng)));
    if (garbage && k % 11 == 4) append(s, encode_witmotion_frame(0x61, {0, 0, 0, 0, 0, 0, 0, 0}));  // not a 0x5X type
  }
  return s;
}

TEST(WitMotionDecoder, ProtocolName) { EXPECT_EQ(make()->protocol(), "witmotion"); }

TEST(WitMotionDecoder, ScalarOptionIsFirstOrLast) {
  EXPECT_NO_THROW(make("first"));
  EXPECT_NO_THROW(make("last"));
  EXPECT_THROW(make("middle"), std::invalid_argument);
  EXPECT_THROW(make(""), std::invalid_argument);
  EXPECT_THROW(make("First"), std::invalid_argument);
  EXPECT_EQ(find_option(kWitMotionDecoder.options, "witmotion_scalar")->default_value, "first");  // the declared default
}

// Frames written by hand from the documented layout (see the top of this file).
TEST(WitMotionDecoder, DocumentLayoutFrames) {
  const Bytes stream = {
      // 0x50 time: 20(18)-02-29 23:59:59, ms 0x036B = 875
      0x55, 0x50, 0x18, 0x02, 0x1D, 0x17, 0x3B, 0x3B, 0x6B, 0x03, 0xD7,
      // 0x51 acceleration: az = 0x0800 = 1 g, temperature 0x0A10; the 0x53 sample carries it
      0x55, 0x51, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0x10, 0x0A, 0xC8,
      // 0x53 angles: roll 0x4000 = 90°, pitch 0xE000 = -45°, yaw 0x8000 = -180°, version 0x1234
      0x55, 0x53, 0x00, 0x40, 0x00, 0xE0, 0x00, 0x80, 0x34, 0x12, 0x8E,
      // 0x59 quaternion: Q0 = 0x7FFF (32767/32768), Q1 = Q2 = Q3 = 0: at rest
      0x55, 0x59, 0xFF, 0x7F, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x2C,
      // 0x59 quaternion: Q0 = Q3 = 0x5A82 (23170/32768 = cos 45°): 90° about Z
      0x55, 0x59, 0x82, 0x5A, 0x00, 0x00, 0x00, 0x00, 0x82, 0x5A, 0x66,
  };
  const Decoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), 3u);
  // Angles: Rz(-180°) Ry(-45°) Rx(90°).
  EXPECT_LT(so3::rotation_angle(r.samples[0].orientation, zyx(-180.0, -45.0, 90.0)), 1e-12);
  EXPECT_LT(so3::rotation_angle(r.samples[1].orientation, Quat::Identity()), 1e-12);
  EXPECT_LT((r.samples[2].orientation * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-12);
  EXPECT_EQ(r.samples[0].flags, kHasDeviceTime | kHasAccel);
  EXPECT_EQ(r.samples[0].accel, Vec3(0, 0, 9.8));
  EXPECT_EQ(r.samples[1].flags, kHasDeviceTime);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_DOUBLE_EQ(r.samples[i].device_time, 23 * 3600 + 59 * 60 + 59 + 0.875);
  }
  // The second 0x59 after one time frame belongs to the next cycle, whose time frame is missing.
  EXPECT_EQ(r.samples[2].flags, 0u);
  for (const auto& s : r.samples) {
    EXPECT_FALSE(s.has_frame_counter);
    EXPECT_NEAR(s.orientation.norm(), 1.0, 1e-15);
  }
  DecoderCounters want;
  want.bytes = stream.size();
  want.frames = 5;
  want.samples = 3;
  want.ignored_frames = 1;  // time
  EXPECT_EQ(r.counters, want);

  // The encoders write the same bytes.
  const auto enc_time = encode_witmotion_time(24, 2, 29, 23, 59, 59, 875);
  EXPECT_TRUE(std::equal(enc_time.begin(), enc_time.end(), stream.begin()));
  const auto enc_angles = encode_witmotion_angles(90.0, -45.0, 180.0, 0x1234);  // 180° wraps to -180°
  EXPECT_TRUE(std::equal(enc_angles.begin(), enc_angles.end(), stream.begin() + 22));
  const auto enc_q = encode_witmotion_quaternion(Quat(std::sqrt(0.5), 0, 0, std::sqrt(0.5)));
  EXPECT_TRUE(std::equal(enc_q.begin(), enc_q.end(), stream.begin() + 44));
}

TEST(WitMotionDecoder, ScalarLastReadsTheFirstThreeAsTheVector) {
  // The 90°-about-Z frame read as x y z w: (x, y, z, w) = (0.707, 0, 0, 0.707), 90° about X.
  const Bytes f = {0x55, 0x59, 0x82, 0x5A, 0x00, 0x00, 0x00, 0x00, 0x82, 0x5A, 0x66};
  const Decoded r = decode(f, "last");
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_LT((r.samples[0].orientation * Vec3::UnitY() - Vec3::UnitZ()).norm(), 1e-12);
}

TEST(WitMotionDecoder, QuaternionRoundTripWithinQuantisation) {
  std::mt19937_64 rng(7);
  // Each component is off by at most 0.5/32768, so the quaternion by at most 1/32768 and the
  // rotation by at most 2/32768 rad (S³ angles are half the rotation angle).
  const double bound = 2.0 / 32768.0 * 1.001;
  double worst = 0.0;
  for (const bool first : {true, false}) {
    for (int i = 0; i < 20000; ++i) {
      const Quat q = random_unit_quaternion(rng);
      const auto f = encode_witmotion_quaternion(q, first);
      const Decoded r = decode(Bytes(f.begin(), f.end()), first ? "first" : "last");
      ASSERT_EQ(r.samples.size(), 1u);
      const double err = so3::rotation_angle(r.samples[0].orientation, q);
      worst = std::max(worst, err);
      ASSERT_LE(err, bound) << q.coeffs().transpose();
      // Component by component, with its own sign kept (the decoder does not flip hemispheres).
      EXPECT_LE((r.samples[0].orientation.coeffs() - q.coeffs()).cwiseAbs().maxCoeff(), 1.5 / 32768.0);
    }
  }
  EXPECT_GT(worst, 0.1 * bound);  // the bound is not vacuous
  // Reading with the other order gives another rotation.
  const Quat q = zyx(30, 20, 10);
  const auto f = encode_witmotion_quaternion(q, true);
  EXPECT_GT(so3::rotation_angle(decode(Bytes(f.begin(), f.end()), "last").samples.at(0).orientation, q), 0.1);
}

TEST(WitMotionDecoder, AnglesRoundTripWithinQuantisation) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> half_turn(-180.0, 180.0), quarter_turn(-90.0, 90.0);
  // Each angle is off by at most half a step of 180/32768°; three of them add up at most.
  const double bound = 3.0 * 0.5 * (180.0 / 32768.0) * kDeg * 1.001;
  for (int i = 0; i < 20000; ++i) {
    const double roll = half_turn(rng), pitch = quarter_turn(rng), yaw = half_turn(rng);
    const auto f = encode_witmotion_angles(roll, pitch, yaw);
    const Decoded r = decode(Bytes(f.begin(), f.end()));
    ASSERT_EQ(r.samples.size(), 1u);
    ASSERT_LE(so3::rotation_angle(r.samples[0].orientation, zyx(yaw, pitch, roll)), bound)
        << roll << " " << pitch << " " << yaw;
  }
}

TEST(WitMotionDecoder, AngleConventions) {
  const auto rotated = [](double roll, double pitch, double yaw, const Vec3& v) {
    const auto f = encode_witmotion_angles(roll, pitch, yaw);
    const Decoded r = decode(Bytes(f.begin(), f.end()));
    return Vec3(r.samples.at(0).orientation * v);
  };
  const double tol = 1e-12;
  EXPECT_LT((rotated(0, 0, 90, Vec3::UnitX()) - Vec3::UnitY()).norm(), tol);   // yaw about Z
  EXPECT_LT((rotated(0, 90, 0, Vec3::UnitX()) + Vec3::UnitZ()).norm(), tol);   // pitch about Y
  EXPECT_LT((rotated(90, 0, 0, Vec3::UnitY()) - Vec3::UnitZ()).norm(), tol);   // roll about X
  // Order Z-Y-X (yaw applied first, about the fixed axes last): Rz(90) Ry(90) z = y, where
  // Ry(90) Rz(90) z would be x.
  EXPECT_LT((rotated(0, 90, 90, Vec3::UnitZ()) - Vec3::UnitY()).norm(), tol);
  // Rz(90) Rx(90) y = z, where Rx(90) Rz(90) y would be -x.
  EXPECT_LT((rotated(90, 0, 90, Vec3::UnitY()) - Vec3::UnitZ()).norm(), tol);
  // Ry(90) Rx(90) y = Ry(90) z = x, where Rx(90) Ry(90) y would be z.
  EXPECT_LT((rotated(90, 90, 0, Vec3::UnitY()) - Vec3::UnitX()).norm(), tol);
}

TEST(WitMotionDecoder, QuaternionAndAnglesOfOneAttitudeAgree) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> half_turn(-180.0, 180.0), quarter_turn(-90.0, 90.0);
  for (int i = 0; i < 1000; ++i) {
    const double roll = half_turn(rng), pitch = quarter_turn(rng), yaw = half_turn(rng);
    const auto fa = encode_witmotion_angles(roll, pitch, yaw);
    const auto fq = encode_witmotion_quaternion(zyx(yaw, pitch, roll));
    const Quat a = decode(Bytes(fa.begin(), fa.end())).samples.at(0).orientation;
    const Quat q = decode(Bytes(fq.begin(), fq.end())).samples.at(0).orientation;
    ASSERT_LT(so3::rotation_angle(a, q), 3e-4);
  }
}

TEST(WitMotionDecoder, QuaternionPreferredOverAngles) {
  const auto a = encode_witmotion_angles(10, 20, 30);
  const auto q = encode_witmotion_quaternion(zyx(-30, -20, -10));
  const Quat qa = zyx(30, 20, 10), qq = zyx(-30, -20, -10);
  Bytes s;
  for (int k = 0; k < 3; ++k) {
    append(s, a);
    append(s, q);
  }
  for (int k = 0; k < 3; ++k) append(s, a);  // the quaternion output switched off
  const Decoded r = decode(s);
  // First cycle: 0x53 before any 0x59, then 0x59; then only 0x59; after the switch-off, the
  // first 0x53 is still taken for the cycle's companion of a 0x59, the next ones give samples.
  const std::vector<Quat> want = {qa, qq, qq, qq, qa, qa};
  ASSERT_EQ(r.samples.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_LT(so3::rotation_angle(r.samples[i].orientation, want[i]), 1e-3) << i;
  EXPECT_EQ(r.counters.frames, 9u);
  EXPECT_EQ(r.counters.ignored_frames, 3u);
  expect_consistent(r);
}

TEST(WitMotionDecoder, DeviceTimeAndDayRollover) {
  const auto q = encode_witmotion_quaternion(Quat::Identity());
  Bytes s;
  append(s, encode_witmotion_time(24, 12, 31, 23, 59, 59, 900));
  append(s, accel_frame());
  append(s, q);
  append(s, encode_witmotion_time(25, 1, 1, 0, 0, 0, 100));  // the next day (and year)
  append(s, accel_frame());
  append(s, q);
  append(s, accel_frame());  // this cycle's time frame was lost
  append(s, q);
  append(s, encode_witmotion_time(25, 1, 1, 0, 0, 0, 300));
  append(s, q);
  append(s, encode_witmotion_time(25, 1, 1, 23, 0, 0, 300));  // a step forward within the day
  append(s, q);
  append(s, encode_witmotion_time(25, 1, 1, 22, 0, 0, 300));  // the clock set back an hour
  append(s, q);
  append(s, encode_witmotion_time(25, 1, 1, 24, 0, 0, 0));  // impossible: malformed, clears the time
  append(s, q);
  append(s, encode_witmotion_time(25, 1, 1, 1, 0, 0, 1000));  // impossible milliseconds
  append(s, q);
  const Decoded r = decode(s);
  ASSERT_EQ(r.samples.size(), 8u);
  const double day = 86400.0;
  EXPECT_EQ(r.samples[0].flags, kHasDeviceTime | kHasAccel);
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, day - 0.1);
  EXPECT_DOUBLE_EQ(r.samples[1].device_time, day + 0.1);
  EXPECT_EQ(r.samples[2].flags, kHasAccel);
  EXPECT_DOUBLE_EQ(r.samples[3].device_time, day + 0.3);
  EXPECT_DOUBLE_EQ(r.samples[4].device_time, day + 23 * 3600 + 0.3);
  EXPECT_DOUBLE_EQ(r.samples[5].device_time, day + 22 * 3600 + 0.3);
  EXPECT_EQ(r.samples[6].flags, 0u);
  EXPECT_EQ(r.samples[7].flags, 0u);
  EXPECT_EQ(r.counters.malformed, 2u);
  expect_consistent(r);

  // reset() forgets the day count; without time frames there is no device time.
  auto d = make();
  Collector sink;
  d->feed(std::span<const std::uint8_t>(s.data(), 22), sink);  // time 23:59:59.9, accel
  d->reset();  // forgets the held acceleration too
  Bytes t;
  append(t, q);
  append(t, encode_witmotion_time(25, 1, 1, 0, 0, 0, 100));
  append(t, q);
  d->feed(t, sink);
  ASSERT_EQ(sink.samples.size(), 2u);
  EXPECT_EQ(sink.samples[0].flags, 0u);
  EXPECT_DOUBLE_EQ(sink.samples[1].device_time, 0.1);
}

TEST(WitMotionDecoder, AnySplitGivesTheSameSamplesAndCounters) {
  std::mt19937_64 rng(3);
  const Bytes stream = motion_stream(rng, 40, true);
  const Decoded whole = decode(stream);
  ASSERT_GT(whole.samples.size(), 30u);
  ASSERT_GT(whole.counters.bad_checksum, 0u);
  ASSERT_GT(whole.counters.resyncs, 0u);
  const auto fresh = [] { return make(); };
  expect_every_split_same(fresh, stream, whole);
  expect_byte_by_byte_same(fresh, stream, whole);
  expect_random_chunkings_same(fresh, stream, whole, rng, 300, {40, 12});  // empty chunks too
  expect_consistent(whole);
}

TEST(WitMotionDecoder, CleanStreamHasNoResyncs) {
  std::mt19937_64 rng(4);
  const Bytes stream = motion_stream(rng, 100, false);
  const Decoded r = decode(stream);
  DecoderCounters want;
  want.bytes = stream.size();
  want.frames = 600;
  want.samples = 101;          // the first cycle's 0x53, then one 0x59 per cycle
  want.ignored_frames = 199;   // 100 time frames, 99 angles
  EXPECT_EQ(r.counters, want);
  // The first cycle's 0x53 carries its accel and gyro, its 0x59 the mag that came between; then
  // each 0x59 carries all three of its cycle.
  ASSERT_EQ(r.samples.size(), 101u);
  EXPECT_EQ(r.samples[0].flags, kHasDeviceTime | kHasAccel | kHasGyro);
  EXPECT_EQ(r.samples[1].flags, kHasDeviceTime | kHasMag);
  for (std::size_t i = 2; i < r.samples.size(); ++i)
    EXPECT_EQ(r.samples[i].flags, kHasDeviceTime | kHasAccel | kHasGyro | kHasMag) << i;
  expect_consistent(r);
}

// Garbage before, between and inside frames, a broken checksum with 0x55 0x59 inside it, and a
// trailing partial frame; every counter derived by hand.
TEST(WitMotionDecoder, ResynchronisationCountedExactly) {
  const auto f1 = encode_witmotion_angles(10, 20, 30);                                       // a sample
  const auto f2 = encode_witmotion_frame(0x51, {0x55, 0x55, 0x55, 0x59, 0x00, 0x55, 0x01, 0x02});  // f4 carries it
  auto f3 = encode_witmotion_frame(0x59, {0x00, 0x40, 0x55, 0x59, 0x00, 0x40, 0x00, 0x40});  // broken below
  f3[10] = static_cast<std::uint8_t>(f3[10] + 1);
  const auto f4 = encode_witmotion_quaternion(zyx(40, 0, 0));  // a sample
  const auto f5 = encode_witmotion_quaternion(zyx(50, 0, 0));  // a sample, split over two feeds
  Bytes s = {0x00, 0x13, 0x55, 0x42};  // G1: 0x55 then a type outside 0x50..0x5F: 4 bytes skipped
  append(s, f1);
  s.insert(s.end(), {0x55, 0x59, 0x01});  // G2: a header, a type, one byte: 3 bytes skipped
  append(s, f2);
  append(s, f3);                          // 11 bytes skipped
  append(s, f4);
  s.insert(s.end(), f5.begin(), f5.begin() + 2);  // held until the rest arrives

  // Preconditions of the hand count: the false starts at G2 and inside f3 fail their checksums,
  // and no other byte of the skipped runs is 0x55.
  const Bytes g2_candidate(s.begin() + 15, s.begin() + 26);
  ASSERT_NE(checksum::sum8({g2_candidate.data(), 10}), g2_candidate[10]);
  const std::size_t f3_at = 4 + 11 + 3 + 11;
  const Bytes f3_inner(s.begin() + f3_at + 4, s.begin() + f3_at + 15);  // 55 59 at data[2], 4 bytes of f4
  ASSERT_EQ(f3_inner[0], 0x55);
  ASSERT_NE(checksum::sum8({f3_inner.data(), 10}), f3_inner[10]);
  for (std::size_t i = f3_at + 1; i < f3_at + 11; ++i) {
    if (i != f3_at + 4) {
      ASSERT_NE(s[i], 0x55) << i;
    }
  }

  auto d = make();
  Collector sink;
  d->feed(s, sink);
  DecoderCounters want;
  want.bytes = s.size();
  want.frames = 3;
  want.samples = 2;
  want.bad_checksum = 3;  // G2's false start, f3, the 0x55 0x59 inside f3
  want.resyncs = 3;       // G1, G2, f3
  want.skipped_bytes = 4 + 3 + 11;
  EXPECT_EQ(d->counters(), want);
  ASSERT_EQ(sink.samples.size(), 2u);
  EXPECT_LT(so3::rotation_angle(sink.samples[0].orientation, zyx(30, 20, 10)), 1e-3);
  EXPECT_LT(so3::rotation_angle(sink.samples[1].orientation, zyx(40, 0, 0)), 1e-3);
  EXPECT_EQ(sink.samples[1].flags, kHasAccel);

  d->feed(std::span<const std::uint8_t>(f5.data() + 2, f5.size() - 2), sink);
  want.bytes += f5.size() - 2;
  want.frames = 4;
  want.samples = 3;
  EXPECT_EQ(d->counters(), want);
  ASSERT_EQ(sink.samples.size(), 3u);
  EXPECT_LT(so3::rotation_angle(sink.samples[2].orientation, zyx(50, 0, 0)), 1e-3);
}

TEST(WitMotionDecoder, ByteInsertedInsideAFrameLosesOnlyThatFrame) {
  const auto a = encode_witmotion_quaternion(zyx(10, 0, 0));
  const auto b = encode_witmotion_quaternion(zyx(20, 0, 0));
  const auto c = encode_witmotion_quaternion(zyx(30, 0, 0));
  Bytes s;
  append(s, a);
  append(s, b);
  s.insert(s.begin() + 11 + 6, 0x77);  // inside b
  append(s, c);
  const Decoded r = decode(s);
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_LT(so3::rotation_angle(r.samples[1].orientation, zyx(30, 0, 0)), 1e-3);
  EXPECT_EQ(r.counters.bad_checksum, 1u);
  EXPECT_EQ(r.counters.resyncs, 1u);
  EXPECT_EQ(r.counters.skipped_bytes, 12u);
}

TEST(WitMotionDecoder, MalformedFrames) {
  Bytes s;
  append(s, encode_witmotion_quaternion(Quat(0, 0, 0, 0)));        // zero quaternion
  append(s, encode_witmotion_quaternion(Quat(0.5, 0.5, 0.5, 0.0)));  // norm 0.87
  append(s, encode_witmotion_angles(0, 90.0, 0));                    // pitch at the limit: fine
  append(s, encode_witmotion_angles(0, 95.0, 0));                    // beyond ±90°
  const Decoded r = decode(s);
  EXPECT_EQ(r.counters.frames, 4u);
  EXPECT_EQ(r.counters.malformed, 3u);
  EXPECT_EQ(r.counters.samples, 1u);
  expect_consistent(r);
}

TEST(WitMotionDecoder, ResetForgetsAPartialFrame) {
  const auto q = encode_witmotion_quaternion(zyx(10, 0, 0));
  auto d = make();
  Collector sink;
  d->feed(std::span<const std::uint8_t>(q.data(), 6), sink);
  d->reset();
  d->feed(std::span<const std::uint8_t>(q.data() + 6, 5), sink);
  EXPECT_TRUE(sink.samples.empty());
  EXPECT_EQ(d->counters().bytes, 11u);
  EXPECT_EQ(d->counters().skipped_bytes, 5u);
  d->feed(q, sink);
  EXPECT_EQ(sink.samples.size(), 1u);
}

// Raw packets written by hand from the documented layouts and formulas (HWT905-TTL "Protocol":
// acceleration int16/32768·16 g with g = 9.8 m/s², angular velocity int16/32768·2000 °/s;
// WT901BLECL Datasheet 6.1.2.1: magnetic field in mG, its example x = 360, y = 105, z = 122).
TEST(WitMotionDecoder, RawPacketsInSIUnits) {
  const Bytes stream = {
      // 0x51: ax 0, ay 0xF800 = -1 g, az 0x0800 = +1 g, temperature 0x0A10 = 25.76 °C
      0x55, 0x51, 0x00, 0x00, 0x00, 0xF8, 0x00, 0x08, 0x10, 0x0A, 0xC0,
      // 0x52: wx 0x0B60 = 2912 -> 177.734375 °/s, wy 0xFFF0 = -16 -> -0.9765625 °/s, wz 0
      0x55, 0x52, 0x60, 0x0B, 0xF0, 0xFF, 0x00, 0x00, 0x10, 0x0A, 0x1B,
      // 0x54: the datasheet's example field, 360 105 122 mG
      0x55, 0x54, 0x68, 0x01, 0x69, 0x00, 0x7A, 0x00, 0x00, 0x00, 0xF5,
      // 0x59 at rest: takes the three readings
      0x55, 0x59, 0xFF, 0x7F, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x2C,
  };
  const Decoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), 1u);
  const DecodedSample& s = r.samples[0];
  EXPECT_EQ(s.flags, kHasAccel | kHasGyro | kHasMag);
  EXPECT_NEAR((s.accel - Vec3(0, -9.8, 9.8)).norm(), 0, 1e-12);
  EXPECT_NEAR((s.gyro - Vec3(177.734375, -0.9765625, 0) * kDeg).norm(), 0, 1e-12);
  EXPECT_NEAR((s.mag - Vec3(36.0, 10.5, 12.2)).norm(), 0, 1e-12);
  EXPECT_EQ(r.counters.frames, 4u);
  EXPECT_EQ(r.counters.ignored_frames, 0u);
  expect_consistent(r);

  // The encoder writes the same bytes.
  const auto acc = encode_witmotion_vector(0x51, Vec3(0, -9.8, 9.8), 0x0A10);
  EXPECT_TRUE(std::equal(acc.begin(), acc.end(), stream.begin()));
  const auto gyr = encode_witmotion_vector(0x52, Vec3(177.734375, -0.9765625, 0) * kDeg, 0x0A10);
  EXPECT_TRUE(std::equal(gyr.begin(), gyr.end(), stream.begin() + 11));
  const auto mag = encode_witmotion_vector(0x54, Vec3(36.0, 10.5, 12.2));
  EXPECT_TRUE(std::equal(mag.begin(), mag.end(), stream.begin() + 22));
}

// A device set to send time, accel, gyro and mag only (no 0x53, no 0x59): raw-only samples, the
// first two when the next cycle starts, then each at its cycle's last packet (0x54).
TEST(WitMotionDecoder, RawOnlyCyclesGiveRawOnlySamples) {
  Bytes s;
  for (int k = 0; k < 4; ++k) {
    append(s, encode_witmotion_time(26, 12, 2, 10, 0, 0, 10 * k));
    append(s, encode_witmotion_vector(0x51, Vec3(0, 0, 9.8 + k)));
    append(s, encode_witmotion_vector(0x52, Vec3(0.5 * k, 0, 0)));
    append(s, encode_witmotion_vector(0x54, Vec3(20, 0, -40)));
  }
  auto d = make();
  Collector sink;
  d->feed(std::span<const std::uint8_t>(s.data(), 44 + 11), sink);  // cycle 1, then cycle 2's time
  ASSERT_EQ(sink.samples.size(), 1u);
  d->feed(std::span<const std::uint8_t>(s.data() + 55, 44), sink);  // cycle 2, then cycle 3's time
  ASSERT_EQ(sink.samples.size(), 2u);
  d->feed(std::span<const std::uint8_t>(s.data() + 99, 33), sink);  // cycle 3 through its 0x54
  ASSERT_EQ(sink.samples.size(), 3u);                              // without waiting for cycle 4
  d->feed(std::span<const std::uint8_t>(s.data() + 132, s.size() - 132), sink);
  ASSERT_EQ(sink.samples.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    const DecodedSample& x = sink.samples[static_cast<std::size_t>(k)];
    EXPECT_EQ(x.flags, kNoOrientation | kHasAccel | kHasGyro | kHasMag | kHasDeviceTime) << k;
    EXPECT_NEAR(x.accel.z(), 9.8 + k, 0.005) << k;
    EXPECT_NEAR(x.gyro.x(), 0.5 * k, 0.002) << k;
    EXPECT_NEAR((x.mag - Vec3(20, 0, -40)).norm(), 0, 1e-12) << k;
    EXPECT_DOUBLE_EQ(x.device_time, 36000.0 + 0.01 * k) << k;
  }
  EXPECT_EQ(d->counters().ignored_frames, 4u);  // the time frames
}

// One lost 0x59 sends its cycle's acceleration alone, and the next cycle's acceleration still
// goes with the next 0x59.
TEST(WitMotionDecoder, LostOrientationFrameSendsItsReadingsAlone) {
  Bytes s;
  for (int k = 0; k < 4; ++k) {
    append(s, encode_witmotion_time(26, 12, 2, 10, 0, 0, 10 * k));
    append(s, encode_witmotion_vector(0x51, Vec3(0, 0, 9.8)));
    auto q = encode_witmotion_quaternion(zyx(10.0 * k, 0, 0));
    if (k == 1) q[10] ^= 1;  // bad checksum
    append(s, q);
  }
  const Decoded r = decode(s);
  ASSERT_EQ(r.samples.size(), 4u);
  EXPECT_EQ(r.samples[0].flags, kHasDeviceTime | kHasAccel);
  EXPECT_EQ(r.samples[1].flags, kHasDeviceTime | kHasAccel | kNoOrientation);
  EXPECT_DOUBLE_EQ(r.samples[1].device_time, 36000.01);  // its own cycle's time
  EXPECT_EQ(r.samples[2].flags, kHasDeviceTime | kHasAccel);
  EXPECT_LT(so3::rotation_angle(r.samples[2].orientation, zyx(20, 0, 0)), 1e-3);
  EXPECT_EQ(r.samples[3].flags, kHasDeviceTime | kHasAccel);
}

// Angles-only output with the magnetic field on: 0x54 comes after the cycle's 0x53, which
// carries accel and gyro; the field goes out alone, never onto the next cycle's orientation.
TEST(WitMotionDecoder, FieldAfterAnglesGoesOutAlone) {
  Bytes s;
  for (int k = 0; k < 3; ++k) {
    append(s, encode_witmotion_vector(0x51, Vec3(0, 0, 9.8)));
    append(s, encode_witmotion_vector(0x52, Vec3(0, 0, 1)));
    append(s, encode_witmotion_angles(10, 0, 0));
    append(s, encode_witmotion_vector(0x54, Vec3(30, 0, 0)));
  }
  const Decoded r = decode(s);
  ASSERT_EQ(r.samples.size(), 6u);
  for (std::size_t k = 0; k < 6; k += 2) {
    EXPECT_EQ(r.samples[k].flags, kHasAccel | kHasGyro) << k;
    EXPECT_EQ(r.samples[k + 1].flags, kNoOrientation | kHasMag) << k;  // when the next 0x51 repeats a type, then at once
  }
  expect_consistent(r);
}

// 10 MB of random bytes: no crash, only unit quaternions, and about as many accepted frames and
// failed checksums as the frame rules predict. At each position a frame is accepted with
// probability 1/256 (0x55) · 16/256 (type 0x50..0x5F) · 1/256 (checksum) = 2^-20, and a checksum
// is tried and fails with probability 1/256 · 16/256 · 255/256. Both counts are close to Poisson.
TEST(WitMotionDecoder, RandomBytes) {
  constexpr std::size_t kBytes = 10'000'000;
  std::mt19937_64 rng(20240229);
  const Bytes data = random_bytes(kBytes, rng);
  for (const char* scalar : {"first", "last"}) {
    const Decoded r = decode_in_random_reads(make(scalar), data, rng);
    const DecoderCounters& c = r.counters;
    EXPECT_EQ(c.bytes, kBytes);
    expect_consistent(r);
    expect_poisson_at_most(c.frames, kBytes / 1048576.0);
    expect_poisson_near(c.bad_checksum, kBytes * (1.0 / 256) * (16.0 / 256) * (255.0 / 256));
    expect_unit_quaternions(r.samples);
  }
}

}  // namespace
}  // namespace posefair::drivers::witmotion_decoder_test
