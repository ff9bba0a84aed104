// posefair's CAN layout (drivers/src/posefair_can_decoder.cpp, docs/can-protocol.md): the
// document's examples byte for byte, round trips through encode_posefair_can, how sets are
// completed and dropped, rollover, frames it does not read, options, and 10 MB of random
// frames. There is no vendor document: docs/can-protocol.md is the specification, and its
// examples are checked here.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "../../support/can_decoder_testing.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"

namespace posefair::drivers::posefair_can_decoder_test {
namespace {

using namespace ::posefair::testing;

CanFrame frame(std::uint32_t id, std::string_view bytes, bool extended = false) {
  return CanFrame::make(id, extended, hex(bytes));
}

CanDecoded decode(const std::vector<CanFrame>& frames, const OptionMap& o = {}) {
  return decode_frames(make_posefair_can_decoder(o), frames);
}

// docs/can-protocol.md, "Example": base 0x200, seq 0x2A, time 1234567 µs, position
// (1, -2, 0.25) m, q = (0.5, -0.5, 0.5, -0.5).
const std::vector<CanFrame> kDocExample = {
    frame(0x200, "2A 87 D6 12 00"),
    frame(0x201, "2A E8 03 30 F8 FA 00"),
    frame(0x202, "00 40 00 C0 00 40 00 C0"),
};

TEST(PosefairCanDecoder, DocumentExampleDecodes) {
  const CanDecoded r = decode(kDocExample);
  ASSERT_EQ(r.samples.size(), 1u);
  const DecodedSample& s = r.samples[0];
  EXPECT_LT((s.orientation.coeffs() - Quat(0.5, -0.5, 0.5, -0.5).coeffs()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(s.flags, std::uint32_t{kHasDeviceTime | kHasPosition});
  EXPECT_DOUBLE_EQ(s.device_time, 1.234567);
  EXPECT_DOUBLE_EQ(s.position.x(), 1.0);
  EXPECT_DOUBLE_EQ(s.position.y(), -2.0);
  EXPECT_DOUBLE_EQ(s.position.z(), 0.25);
  EXPECT_TRUE(s.has_frame_counter);
  EXPECT_EQ(s.frame_counter, 0x2Au);
  EXPECT_EQ(r.counters.frames, 3u);
  EXPECT_EQ(r.counters.bytes, 20u);
  EXPECT_EQ(r.counters.skipped_bytes, 0u);
}

TEST(PosefairCanDecoder, DocumentQuaternionOnlyExample) {
  // The identity, alone: 0x7FFF = 32767 is exactly 1.
  const CanDecoded r = decode({frame(0x202, "FF 7F 00 00 00 00 00 00")});
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].orientation.coeffs(), Quat::Identity().coeffs());
  EXPECT_EQ(r.samples[0].flags, 0u);
  EXPECT_FALSE(r.samples[0].has_frame_counter);
}

TEST(PosefairCanDecoder, EncoderWritesTheDocumentExample) {
  const Vec3 p(1.0, -2.0, 0.25);
  const std::vector<CanFrame> f = encode_posefair_can(0x200, false, Quat(0.5, -0.5, 0.5, -0.5), 1234567, &p, 0x2A);
  ASSERT_EQ(f.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(f[k].can_id, kDocExample[k].can_id) << k;
    ASSERT_EQ(f[k].len, kDocExample[k].len) << k;
    EXPECT_TRUE(std::equal(f[k].data.begin(), f[k].data.begin() + f[k].len, kDocExample[k].data.begin())) << k;
  }
}

// docs/can-protocol.md, "Raw IMU example": seq 0x2B, time 1244567 µs, gyroscope (0.5, -0.25,
// 0.125) rad/s, accelerometer (0.5, -1, 9.81) m/s², magnetometer (20, -5, -40) µT.
const std::vector<CanFrame> kRawExample = {
    frame(0x200, "2B 97 FD 12 00"),
    frame(0x203, "2B 00 F4 01 06 FF 7D 00"),
    frame(0x203, "2B 01 32 00 9C FF D5 03"),
    frame(0x203, "2B 82 D0 07 0C FE 60 F0"),
};

TEST(PosefairCanDecoder, RawImuDocumentExample) {
  const CanDecoded r = decode(kRawExample);
  ASSERT_EQ(r.samples.size(), 1u);
  const DecodedSample& s = r.samples[0];
  EXPECT_EQ(s.flags, kNoOrientation | kHasDeviceTime | kHasGyro | kHasAccel | kHasMag);
  EXPECT_DOUBLE_EQ(s.device_time, 1.244567);
  EXPECT_NEAR((s.gyro - Vec3(0.5, -0.25, 0.125)).norm(), 0, 1e-12);
  EXPECT_NEAR((s.accel - Vec3(0.5, -1, 9.81)).norm(), 0, 1e-12);
  EXPECT_NEAR((s.mag - Vec3(20, -5, -40)).norm(), 0, 1e-12);
  EXPECT_EQ(s.frame_counter, 0x2Bu);
  EXPECT_EQ(r.counters.frames, 4u);
  EXPECT_EQ(r.counters.resyncs, 0u);  // the TIME frame was taken by the raw set, not dropped
  EXPECT_EQ(r.counters.skipped_bytes, 0u);

  const Vec3 g(0.5, -0.25, 0.125), a(0.5, -1, 9.81), m(20, -5, -40);
  std::vector<CanFrame> enc = encode_posefair_can_raw(0x200, false, &g, &a, &m, 0x2B);
  ASSERT_EQ(enc.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(enc[k].can_id, kRawExample[k + 1].can_id) << k;
    EXPECT_TRUE(std::equal(enc[k].data.begin(), enc[k].data.begin() + 8, kRawExample[k + 1].data.begin())) << k;
  }
}

// A tracker that sends its quaternion and its readings each period: the quaternion completes
// its sample with the time; the RAW set after it is a raw-only sample with the same time.
TEST(PosefairCanDecoder, RawSetAfterTheQuaternionTakesItsTime) {
  std::vector<CanFrame> stream;
  const Vec3 g(0.01, 0, 0), a(0, 0, 9.81);
  for (std::uint8_t k = 0; k < 3; ++k) {
    const auto q = encode_posefair_can(0x200, false, Quat::Identity(), 1000u * k, nullptr, k);
    const auto raw = encode_posefair_can_raw(0x200, false, &g, &a, nullptr, k);
    stream.insert(stream.end(), q.begin(), q.end());
    stream.insert(stream.end(), raw.begin(), raw.end());
  }
  const CanDecoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), 6u);
  for (std::size_t k = 0; k < 6; k += 2) {
    EXPECT_EQ(r.samples[k].flags, kHasDeviceTime) << k;
    EXPECT_EQ(r.samples[k + 1].flags, kNoOrientation | kHasDeviceTime | kHasGyro | kHasAccel) << k;
    EXPECT_DOUBLE_EQ(r.samples[k + 1].device_time, r.samples[k].device_time) << k;
  }
  EXPECT_EQ(r.counters.resyncs, 0u);
}

TEST(PosefairCanDecoder, BrokenRawSetsAreDroppedAndBadRawFramesMalformed) {
  const CanDecoded r = decode({
      frame(0x203, "01 00 01 00 02 00 03 00"),  // gyro of seq 1, its end lost
      frame(0x203, "02 00 01 00 02 00 03 00"),  // seq 2: drops seq 1's set (resync, 8 bytes)
      frame(0x203, "02 00 01 00 02 00 03 00"),  // gyro again: drops seq 2's set
      frame(0x203, "02 83 00 00 00 00 00 00"),  // kind 3: malformed
      frame(0x203, "02 40 00 00 00 00 00 00"),  // reserved bit: malformed
      frame(0x203, "02 81 00 00"),              // short: malformed
      frame(0x203, "02 81 00 00 00 00 E8 03"),  // accel, last: completes with the held gyro
  });
  EXPECT_EQ(r.counters.resyncs, 2u);
  EXPECT_EQ(r.counters.malformed, 3u);
  EXPECT_EQ(r.counters.skipped_bytes, 16u + 8u + 8u + 4u);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].flags, kNoOrientation | kHasGyro | kHasAccel);  // no TIME of seq 2
  EXPECT_NEAR(r.samples[0].accel.z(), 10.0, 1e-12);
  EXPECT_NEAR((r.samples[0].gyro - Vec3(0.001, 0.002, 0.003)).norm(), 0, 1e-15);
}

// The quaternion rotates sensor coordinates into the world: +90° about z maps x onto +y.
TEST(PosefairCanDecoder, NoConjugateSensorToWorld) {
  const double h = std::sqrt(0.5);
  const CanDecoded r = decode(encode_posefair_can(0x200, false, Quat(h, 0, 0, h), std::nullopt, nullptr, 0));
  ASSERT_EQ(r.samples.size(), 1u);
  const Vec3 v = r.samples[0].orientation * Vec3::UnitX();
  EXPECT_NEAR(v.y(), 1.0, 1e-4);
  EXPECT_NEAR(v.x(), 0.0, 1e-4);
}

TEST(PosefairCanDecoder, RoundTripsRandomSamples) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> metres(-30.0, 30.0);
  for (int variant = 0; variant < 8; ++variant) {
    const bool with_time = variant & 1, with_position = variant & 2, extended = variant & 4;
    OptionMap o;
    o["posefair_base_id"] = std::string(extended ? "0x1ABCDE00" : "0x7F0");
    o["posefair_id_format"] = std::string(extended ? "extended" : "standard");
    const std::uint32_t base = extended ? 0x1ABCDE00 : 0x7F0;
    std::vector<CanFrame> stream;
    std::vector<Quat> qs;
    std::vector<Vec3> ps;
    for (int k = 0; k < 300; ++k) {
      qs.push_back(random_unit_quaternion(rng));
      ps.emplace_back(metres(rng), metres(rng), metres(rng));
      const auto f = encode_posefair_can(base, extended, qs.back(), with_time ? std::optional<std::uint32_t>(1000u * k) : std::nullopt,
                                         with_position ? &ps.back() : nullptr, static_cast<std::uint8_t>(k));
      stream.insert(stream.end(), f.begin(), f.end());
    }
    const CanDecoded r = decode(stream, o);
    ASSERT_EQ(r.samples.size(), qs.size()) << variant;
    EXPECT_EQ(r.counters.frames, stream.size());
    EXPECT_EQ(r.counters.skipped_bytes + r.counters.malformed + r.counters.resyncs, 0u);
    for (std::size_t k = 0; k < qs.size(); ++k) {
      const DecodedSample& s = r.samples[k];
      // int16 rounding: each component within 0.5/32767 before normalising
      const Quat& q = qs[k];
      EXPECT_LT(std::min((s.orientation.coeffs() - q.coeffs()).cwiseAbs().maxCoeff(),
                         (s.orientation.coeffs() + q.coeffs()).cwiseAbs().maxCoeff()),
                1e-4);
      EXPECT_NEAR(s.orientation.norm(), 1.0, 1e-15);
      EXPECT_EQ(s.has_frame_counter, with_time || with_position);
      if (with_time || with_position) {
        EXPECT_EQ(s.frame_counter, k);  // seq unwrapped past 255
      }
      EXPECT_EQ((s.flags & kHasDeviceTime) != 0, with_time);
      if (with_time) {
        EXPECT_DOUBLE_EQ(s.device_time, 1e-3 * static_cast<double>(k));
      }
      EXPECT_EQ((s.flags & kHasPosition) != 0, with_position);
      if (with_position) {
        EXPECT_LE((s.position - ps[k]).cwiseAbs().maxCoeff(), 0.0005 + 1e-12);
      }
    }
  }
}

TEST(PosefairCanDecoder, PartialSetIsDroppedWhenTheSequenceMovesOn) {
  const Vec3 p(0.1, 0.2, 0.3);
  auto s1 = encode_posefair_can(0x200, false, Quat::Identity(), 100, &p, 1);
  auto s2 = encode_posefair_can(0x200, false, Quat(0, 1, 0, 0), 200, &p, 2);
  // Sample 1's quaternion is lost: its time and position must not go to sample 2.
  const CanDecoded r = decode({s1[0], s1[1], s2[0], s2[1], s2[2]});
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].frame_counter, 2u);
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 200e-6);
  EXPECT_EQ(r.counters.resyncs, 1u);
  EXPECT_EQ(r.counters.skipped_bytes, 5u + 7u);
  // Only the time frame of sample 2 arrives: the sample has no position.
  const CanDecoded t = decode({s1[0], s1[1], s1[2], s2[0], s2[2]});
  ASSERT_EQ(t.samples.size(), 2u);
  EXPECT_EQ(t.samples[1].flags, std::uint32_t{kHasDeviceTime});
  EXPECT_EQ(t.counters.resyncs, 0u);
}

TEST(PosefairCanDecoder, RepeatedKindInASetStartsANewSet) {
  const auto a = encode_posefair_can(0x200, false, Quat::Identity(), 100, nullptr, 5);
  const auto b = encode_posefair_can(0x200, false, Quat::Identity(), 300, nullptr, 5);  // same seq, another time frame
  const CanDecoded r = decode({a[0], b[0], b[1]});
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 300e-6);
  EXPECT_EQ(r.counters.resyncs, 1u);
}

TEST(PosefairCanDecoder, MalformedFramesAreCountedAndABadQuaternionDropsItsSet) {
  const auto good = encode_posefair_can(0x200, false, Quat(0, 0, 1, 0), 7, nullptr, 9);
  const std::vector<CanFrame> bad = {
      frame(0x202, "FF 7F 00 00 00 00 00"),     // 7 bytes
      frame(0x202, "00 80 00 00 00 00 00 00"),  // w = -32768
      frame(0x202, "FF 3F 00 00 00 00 00 00"),  // norm 0.5
      frame(0x202, "00 00 00 00 00 00 00 00"),  // zero
      frame(0x200, "01 00 00 00"),              // time frame, 4 bytes
      frame(0x201, "01 00 00 00 00 00 00 00"),  // position frame, 8 bytes
  };
  for (std::size_t k = 0; k < bad.size(); ++k) {
    const auto set = encode_posefair_can(0x200, false, Quat::Identity(), 5, nullptr, 8);
    const CanDecoded r = decode({set[0], bad[k], good[0], good[1]});
    EXPECT_EQ(r.counters.malformed, 1u) << k;
    ASSERT_EQ(r.samples.size(), 1u) << k;
    EXPECT_EQ(r.samples[0].frame_counter, 9u) << k;
    // Either way the time frame of seq 8 is given up: a bad quaternion drops it; a bad time or
    // position frame leaves it open until seq 9 moves on.
    EXPECT_EQ(r.counters.resyncs, 1u) << k;
  }
}

TEST(PosefairCanDecoder, DeviceTimeAndSequenceRollOver) {
  std::vector<CanFrame> stream;
  const std::uint32_t times[] = {0xFFFFFF00u, 0xFFFFFFFFu, 0x10u, 0x1000u};
  const std::uint8_t seqs[] = {254, 255, 0, 1};
  for (int k = 0; k < 4; ++k) {
    const auto f = encode_posefair_can(0x200, false, Quat::Identity(), times[k], nullptr, seqs[k]);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  const CanDecoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), 4u);
  const double wrap = 4294967296.0;
  const double expected[] = {0xFFFFFF00u * 1e-6, 0xFFFFFFFFu * 1e-6, (wrap + 0x10) * 1e-6, (wrap + 0x1000) * 1e-6};
  const std::uint64_t counters[] = {254, 255, 256, 257};
  for (int k = 0; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(r.samples[k].device_time, expected[k]) << k;
    EXPECT_EQ(r.samples[k].frame_counter, counters[k]) << k;
  }
}

TEST(PosefairCanDecoder, ResetForgetsThePendingSetAndRollover) {
  auto d = make_posefair_can_decoder();
  Collector c;
  for (const auto& f : encode_posefair_can(0x200, false, Quat::Identity(), 0xFFFFFFF0u, nullptr, 200)) d->feed(f, c);
  d->feed(encode_posefair_can(0x200, false, Quat::Identity(), 5, nullptr, 201)[0], c);  // a pending time frame
  d->reset();
  d->feed(encode_posefair_can(0x200, false, Quat::Identity(), std::nullopt, nullptr, 0)[0], c);
  for (const auto& f : encode_posefair_can(0x200, false, Quat::Identity(), 3, nullptr, 7)) d->feed(f, c);
  ASSERT_EQ(c.samples.size(), 3u);
  EXPECT_EQ(c.samples[1].flags, 0u);  // the pending time frame was forgotten
  EXPECT_DOUBLE_EQ(c.samples[2].device_time, 3e-6);  // not unwrapped past 2^32
  EXPECT_EQ(c.samples[2].frame_counter, 7u);
}

TEST(PosefairCanDecoder, OtherFramesChangeNothingAndFiltersPassItsFrames) {
  std::mt19937_64 rng(4);
  std::vector<CanFrame> stream;
  const Vec3 p(1, 2, 3);
  for (int k = 0; k < 50; ++k) {
    const auto f = encode_posefair_can(0x200, false, random_unit_quaternion(rng), 10u * k, k % 2 ? &p : nullptr, static_cast<std::uint8_t>(k));
    stream.insert(stream.end(), f.begin(), f.end());
  }
  auto with = make_posefair_can_decoder();
  auto without = make_posefair_can_decoder();
  const Vec3 g(0.1, 0.2, 0.3);
  const auto raw = encode_posefair_can_raw(0x200, false, &g, nullptr, nullptr, 7);
  stream.insert(stream.end(), raw.begin(), raw.end());
  // 0x204 (B + 4), 0x1FF (B - 1), and 0x202 as an extended identifier are not its frames.
  expect_other_frames_change_nothing(*with, *without, stream, {0x204, 0x1FF, 0x202 | CanFrame::kEffFlag});
  expect_filters_pass(with->filters(), stream,
                      {0x204, 0x1FF, 0x202 | CanFrame::kEffFlag, 0x203 | CanFrame::kRtrFlag, 0x602});
}

TEST(PosefairCanDecoder, OptionsAreCheckedAndTheRegistryKnowsIt) {
  EXPECT_EQ(make_can_decoder("posefair-can")->protocol(), "posefair-can");
  EXPECT_EQ(make_can_decoder("no-such-protocol"), nullptr);
  const auto names = can_decoder_protocols();
  EXPECT_TRUE(std::find(names.begin(), names.end(), "posefair-can") != names.end());
  OptionMap o;
  o["posefair_base_id"] = std::string("0x7FD");  // B + 3 would be 0x800
  EXPECT_THROW(make_posefair_can_decoder(o), std::invalid_argument);
  o["posefair_base_id"] = std::string("0x7FC");
  EXPECT_NO_THROW(make_posefair_can_decoder(o));
  o["posefair_base_id"] = std::string("512");
  const CanDecoded r = decode(kDocExample, o);
  EXPECT_EQ(r.samples.size(), 1u);
  for (const char* bad : {"", "0x", "-1", "12a", "0x1G", "99999999999"}) {
    o["posefair_base_id"] = std::string(bad);
    EXPECT_THROW(make_posefair_can_decoder(o), std::invalid_argument) << bad;
  }
  o["posefair_base_id"] = std::string("0x200");
  o["posefair_id_format"] = std::string("long");
  EXPECT_THROW(make_posefair_can_decoder(o), std::invalid_argument);
}

// 10 MB of random frames carrying its three identifiers: no crash; every sample a unit
// quaternion; every byte used, skipped or held. There is no checksum in the payload (the bus's
// CRC protects frames), so random quaternion frames are accepted at the rate a random point of
// the cube [-1, 1]^4 lies within 1e-3 of the unit sphere: π²/2 · (1.001⁴ − 0.999⁴) / 16.
TEST(PosefairCanDecoder, RandomFramesAreAcceptedAtTheGeometricRate) {
  std::mt19937_64 rng(20261201);
  const std::vector<std::uint32_t> ids = {0x200, 0x201, 0x202};
  const std::vector<CanFrame> frames = random_frames(2'600'000, ids, rng);
  ASSERT_GE(payload_bytes(frames), 10'000'000u);
  std::uint64_t candidates = 0;  // quaternion frames of 8 bytes without -32768
  for (const auto& f : frames) {
    bool ok = f.id() == 0x202 && f.len == 8;
    for (int k = 0; ok && k < 4; ++k) ok = !(f.data[2 * k] == 0x00 && f.data[2 * k + 1] == 0x80);
    candidates += ok;
  }
  const CanDecoded r = decode(frames);
  const double p = std::numbers::pi * std::numbers::pi / 2.0 * (std::pow(1.001, 4) - std::pow(0.999, 4)) / 16.0;
  expect_binomial_within(r.counters.samples, static_cast<double>(candidates), p);
  expect_unit_quaternions(r.samples);
  const DecoderCounters& k = r.counters;
  EXPECT_EQ(k.bytes, payload_bytes(frames));
  EXPECT_GT(k.malformed, frames.size() / 2);
  EXPECT_GT(k.resyncs, 0u);
  for (const auto& s : r.samples) ASSERT_TRUE(std::isfinite(s.device_time) && s.position.allFinite());
}

// 10 MB of random quaternion frames (8 bytes each): accepted at the rate a random point of the
// cube [-1, 1]^4 lies within 1e-3 of the unit sphere, π²/2 · (1.001⁴ − 0.999⁴) / 16 ≈ 0.25%
// (about 3100 of 1.25 million, ± 55): a tolerance 20% wider or narrower would be caught.
TEST(PosefairCanDecoder, RandomQuaternionFramesPassTheNormCheckAtTheGeometricRate) {
  std::mt19937_64 rng(102);
  std::vector<CanFrame> frames = random_frames(1'250'000, {0x202}, rng);
  std::uint64_t candidates = 0;  // no component -32768
  for (auto& f : frames) {
    f.len = 8;
    bool ok = true;
    for (int k = 0; ok && k < 4; ++k) ok = !(f.data[2 * k] == 0x00 && f.data[2 * k + 1] == 0x80);
    candidates += ok;
  }
  const CanDecoded r = decode(frames);
  const double p = std::numbers::pi * std::numbers::pi / 2.0 * (std::pow(1.001, 4) - std::pow(0.999, 4)) / 16.0;
  expect_binomial_within(r.counters.samples, static_cast<double>(candidates), p);
  EXPECT_EQ(r.counters.samples + r.counters.malformed, frames.size());
  expect_unit_quaternions(r.samples);
}

}  // namespace
}  // namespace posefair::drivers::posefair_can_decoder_test
