// The Xsens MTi CAN decoder (drivers/src/xsens_can_decoder.cpp): documented values, pairing of
// SampleTime and GroupCounter with the quaternion, raw readings gathered per group, round trips
// through encode_xsens_can, malformed frames, rollover, identifiers and options, and 10 MB of
// random frames.
//
// Byte-exact examples: none of the Xsens documents found shows a captured CAN frame. The
// frames below follow the documented layout (MT1604P / Movella "CAN Messages": XCDI_Quaternion
// 0x021, four int16 big-endian; 1.0 is 0x7FFF, -1.0 is 0x8001, the page's "be careful when
// converting the value 1"; XCID_SampleTime 0x005 uint32; XCID_GroupCounter 0x006 uint16;
// XCDI_RateOfTurn 0x032, XCDI_Acceleration 0x034, XCDI_MagneticField 0x041: three int16
// big-endian each, scaled 2^-9 rad/s, 2^-8 m/s², 2^-10 a.u.).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "../../support/can_decoder_testing.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"

namespace posefair::drivers::xsens_can_decoder_test {
namespace {

using namespace ::posefair::testing;

CanFrame frame(std::uint32_t id, std::string_view bytes, bool extended = false) {
  return CanFrame::make(id, extended, hex(bytes));
}

CanDecoded decode(const std::vector<CanFrame>& frames, const OptionMap& o = {}) {
  return decode_frames(make_xsens_can_decoder(o), frames);
}

TEST(XsensCanDecoder, DocumentedValuesDecode) {
  const CanDecoded r = decode({
      frame(0x021, "7F FF 00 00 00 00 00 00"),  // identity
      frame(0x021, "80 01 00 00 00 00 00 00"),  // -identity (-1.0 is -32767)
      frame(0x021, "76 41 00 00 00 00 30 FB"),  // 45° about z: round(32767 cos 22.5°), round(32767 sin 22.5°)
  });
  ASSERT_EQ(r.samples.size(), 3u);
  EXPECT_EQ(r.samples[0].orientation.coeffs(), Quat::Identity().coeffs());
  EXPECT_EQ(r.samples[1].orientation.coeffs(), Quat(-1, 0, 0, 0).coeffs());
  const Quat yaw45(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  EXPECT_LT((r.samples[2].orientation.coeffs() - yaw45.coeffs()).cwiseAbs().maxCoeff(), 3e-5);
  EXPECT_EQ(r.counters.frames, 3u);
  EXPECT_EQ(r.counters.bytes, 24u);
}

TEST(XsensCanDecoder, TimeAndCounterGoWithTheNextQuaternion) {
  const CanDecoded r = decode({
      frame(0x006, "12 34"),                    // GroupCounter 0x1234
      frame(0x005, "00 01 E2 40"),              // SampleTime 123456 ticks
      frame(0x021, "7F FF 00 00 00 00 00 00"),
      frame(0x021, "7F FF 00 00 00 00 00 00"),  // no time or counter since the previous quaternion
  });
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.samples[0].flags, std::uint32_t{kHasDeviceTime});
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 12.3456);  // 10 kHz ticks
  EXPECT_TRUE(r.samples[0].has_frame_counter);
  EXPECT_EQ(r.samples[0].frame_counter, 0x1234u);
  EXPECT_EQ(r.samples[1].flags, 0u);
  EXPECT_FALSE(r.samples[1].has_frame_counter);
  OptionMap us;
  us["xsens_sample_time_unit"] = std::string("1us");
  const CanDecoded u = decode({frame(0x005, "00 01 E2 40"), frame(0x021, "7F FF 00 00 00 00 00 00")}, us);
  ASSERT_EQ(u.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(u.samples[0].device_time, 0.123456);
}

TEST(XsensCanDecoder, ANewerTimeReplacesAnOlderOne) {
  const CanDecoded r = decode({frame(0x005, "00 00 00 01"), frame(0x005, "00 00 00 02"), frame(0x021, "7F FF 00 00 00 00 00 00")});
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 2e-4);
  EXPECT_EQ(r.counters.ignored_frames, 1u);
  EXPECT_EQ(r.counters.frames, 3u);
}

TEST(XsensCanDecoder, RoundTripsRandomOrientations) {
  std::mt19937_64 rng(5);
  std::vector<CanFrame> stream;
  std::vector<Quat> qs;
  for (int k = 0; k < 500; ++k) {
    qs.push_back(random_unit_quaternion(rng));
    const auto f = encode_xsens_can(qs.back(), 0xFFFFFF00u + 40u * static_cast<std::uint32_t>(k), static_cast<std::uint16_t>(65500 + k));
    stream.insert(stream.end(), f.begin(), f.end());
  }
  const CanDecoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), qs.size());
  EXPECT_EQ(r.counters.frames, stream.size());
  EXPECT_EQ(r.counters.malformed + r.counters.skipped_bytes + r.counters.ignored_frames, 0u);
  for (std::size_t k = 0; k < qs.size(); ++k) {
    const DecodedSample& s = r.samples[k];
    EXPECT_LT((s.orientation.coeffs() - qs[k].coeffs()).cwiseAbs().maxCoeff(), 1e-4) << k;
    EXPECT_EQ(s.frame_counter, 65500u + k);  // unwrapped past 65535
    EXPECT_DOUBLE_EQ(s.device_time, (0xFFFFFF00u + 40.0 * static_cast<double>(k)) * 1e-4);  // unwrapped past 2^32
  }
}

TEST(XsensCanDecoder, QuaternionIsSensorToEarth) {
  const double h = std::sqrt(0.5);
  const CanDecoded r = decode(encode_xsens_can(Quat(h, 0, 0, h), std::nullopt, std::nullopt));
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_NEAR((r.samples[0].orientation * Vec3::UnitX()).y(), 1.0, 1e-4);
}

OptionMap raw_options(std::vector<std::string> kinds = {"rate_of_turn", "acceleration", "magnetic_field"}) {
  OptionMap o;
  o["xsens_raw"] = std::move(kinds);
  return o;
}

// One group: SampleTime 1000 ticks, identity, rate of turn (1, -1, 0.25) rad/s, acceleration
// (0, 0, 9.80859375) m/s², magnetic field (0.25, 0, -0.25) a.u.
const std::vector<CanFrame> kRawGroup = {
    frame(0x005, "00 00 03 E8"),
    frame(0x021, "7F FF 00 00 00 00 00 00"),
    frame(0x032, "02 00 FE 00 00 80"),  // 512, -512, 128 · 2^-9
    frame(0x034, "00 00 00 00 09 CF"),  // 2511 · 2^-8 = 9.80859375
    frame(0x041, "01 00 00 00 FF 00"),  // 256, 0, -256 · 2^-10
};

TEST(XsensCanRaw, DocumentedValuesDecodeAndTheGroupIsEmittedAtItsLastMessage) {
  auto d = make_xsens_can_decoder(raw_options());
  Collector c;
  for (std::size_t k = 0; k + 1 < kRawGroup.size(); ++k) d->feed(kRawGroup[k], c);
  EXPECT_TRUE(c.samples.empty());  // the magnetic field is still to come
  d->feed(kRawGroup.back(), c);
  ASSERT_EQ(c.samples.size(), 1u);
  const DecodedSample& s = c.samples[0];
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kHasDeviceTime | kHasGyro | kHasAccel | kHasMag));
  EXPECT_EQ(s.orientation.coeffs(), Quat::Identity().coeffs());
  EXPECT_EQ(s.gyro, Vec3(1.0, -1.0, 0.25));
  EXPECT_EQ(s.accel, Vec3(0.0, 0.0, 9.80859375));
  EXPECT_EQ(s.mag, Vec3(12.5, 0.0, -12.5));  // a.u. · 50 µT (xsens_mag_field's default)
  EXPECT_DOUBLE_EQ(s.device_time, 0.1);
  // The encoder writes these frames.
  std::vector<CanFrame> encoded = encode_xsens_can(Quat::Identity(), 1000, std::nullopt);
  const std::vector<CanFrame> raw = encode_xsens_can_raw(Vec3(1.0, -1.0, 0.25), Vec3(0.0, 0.0, 9.80859375), Vec3(0.25, 0.0, -0.25));
  encoded.insert(encoded.end(), raw.begin(), raw.end());
  ASSERT_EQ(encoded.size(), kRawGroup.size());
  for (std::size_t k = 0; k < encoded.size(); ++k) {
    EXPECT_EQ(encoded[k].id(), kRawGroup[k].id()) << k;
    EXPECT_EQ(std::vector<std::uint8_t>(encoded[k].data.begin(), encoded[k].data.begin() + encoded[k].len),
              std::vector<std::uint8_t>(kRawGroup[k].data.begin(), kRawGroup[k].data.begin() + kRawGroup[k].len)) << k;
  }
  // Only the listed messages are read: with the magnetic field left out the group ends at the
  // acceleration, and the field's frame is foreign.
  OptionMap two = raw_options({"rate_of_turn", "acceleration"});
  two["xsens_mag_field"] = 48.0;
  const CanDecoded r = decode(kRawGroup, two);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].flags, static_cast<std::uint32_t>(kHasDeviceTime | kHasGyro | kHasAccel));
  EXPECT_EQ(r.frame_counters.foreign, 1u);
}

TEST(XsensCanRaw, ALostFrameCostsOnlyItsReading) {
  std::vector<CanFrame> stream;
  const auto group = [&](std::uint32_t time, bool quaternion, bool acceleration) {
    stream.push_back(frame(0x005, "00 00 00 00"));
    stream.back().data[3] = static_cast<std::uint8_t>(time);
    if (quaternion) stream.push_back(kRawGroup[1]);
    stream.push_back(kRawGroup[2]);
    if (acceleration) stream.push_back(kRawGroup[3]);
    stream.push_back(kRawGroup[4]);
  };
  group(1, true, true);
  group(2, true, false);   // its acceleration lost: emitted when group 3 starts, without it
  group(3, false, true);   // its quaternion lost: a raw-only sample
  group(4, true, true);
  const CanDecoded r = decode(stream, raw_options());
  ASSERT_EQ(r.samples.size(), 4u);
  EXPECT_EQ(r.samples[1].flags, static_cast<std::uint32_t>(kHasDeviceTime | kHasGyro | kHasMag));
  EXPECT_EQ(r.samples[2].flags, static_cast<std::uint32_t>(kHasDeviceTime | kHasGyro | kHasAccel | kHasMag | kNoOrientation));
  for (std::size_t k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(r.samples[k].device_time, 1e-4 * static_cast<double>(k + 1)) << k;
  EXPECT_EQ(r.samples[3].flags, static_cast<std::uint32_t>(kHasDeviceTime | kHasGyro | kHasAccel | kHasMag));
  EXPECT_EQ(r.counters.samples, 4u);
  EXPECT_EQ(r.counters.malformed, 0u);
  // A raw frame of the wrong size is malformed and the group goes on without it.
  std::vector<CanFrame> bad = kRawGroup;
  bad[2] = frame(0x032, "02 00 FE 00 00");
  const CanDecoded m = decode(bad, raw_options({"rate_of_turn", "acceleration"}));
  EXPECT_EQ(m.counters.malformed, 1u);
  EXPECT_EQ(m.samples.size(), 0u);  // waiting for its rate of turn until the next group starts
}

TEST(XsensCanRaw, RoundTripsRandomReadings) {
  std::mt19937_64 rng(12);
  std::normal_distribution<double> n;
  std::vector<CanFrame> stream;
  std::vector<std::array<Vec3, 3>> truth;
  for (int k = 0; k < 200; ++k) {
    const std::array<Vec3, 3> v = {Vec3(n(rng), n(rng), n(rng)) * 5.0, Vec3(n(rng), n(rng), n(rng)) * 20.0,
                                   Vec3(n(rng), n(rng), n(rng)) * 0.5};
    truth.push_back(v);
    const auto q = encode_xsens_can(random_unit_quaternion(rng), 100u * static_cast<std::uint32_t>(k), static_cast<std::uint16_t>(k));
    const auto raw = encode_xsens_can_raw(v[0], v[1], v[2]);
    stream.insert(stream.end(), q.begin(), q.end());
    stream.insert(stream.end(), raw.begin(), raw.end());
  }
  const CanDecoded r = decode(stream, raw_options());
  ASSERT_EQ(r.samples.size(), truth.size());
  for (std::size_t k = 0; k < truth.size(); ++k) {
    EXPECT_LT((r.samples[k].gyro - truth[k][0]).cwiseAbs().maxCoeff(), 0.5 / 512 + 1e-12) << k;  // half a step
    EXPECT_LT((r.samples[k].accel - truth[k][1]).cwiseAbs().maxCoeff(), 0.5 / 256 + 1e-12) << k;
    EXPECT_LT((r.samples[k].mag - 50.0 * truth[k][2]).cwiseAbs().maxCoeff(), 50.0 * 0.5 / 1024 + 1e-12) << k;
    EXPECT_EQ(r.samples[k].frame_counter, k);
  }
  expect_filters_pass(make_xsens_can_decoder(raw_options())->filters(), stream, {0x022, 0x035, 0x061});
}

TEST(XsensCanRaw, OptionsAreChecked) {
  EXPECT_THROW(make_xsens_can_decoder(raw_options({"gyro"})), std::invalid_argument);
  EXPECT_THROW(make_xsens_can_decoder(raw_options({"acceleration", "acceleration"})), std::invalid_argument);
  OptionMap o = raw_options();
  o["xsens_acceleration_id"] = std::string("0x021");  // the quaternion's
  try {
    make_xsens_can_decoder(o);
    ADD_FAILURE() << "accepted an identifier used twice";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.key(), "xsens_acceleration_id");
  }
  o = raw_options({"rate_of_turn"});
  o["xsens_acceleration_id"] = std::string("0x021");  // not listed: not read, so no clash
  EXPECT_NE(make_xsens_can_decoder(o), nullptr);
  o = raw_options();
  o["xsens_mag_field"] = 0.0;
  EXPECT_THROW(make_xsens_can_decoder(o), std::invalid_argument);
}

TEST(XsensCanDecoder, MalformedFramesAreCounted) {
  const std::vector<CanFrame> bad = {
      frame(0x021, "7F FF 00 00 00 00 00"),     // 7 bytes
      frame(0x021, "80 00 00 00 00 00 00 00"),  // -32768
      frame(0x021, "40 00 00 00 00 00 00 00"),  // norm 0.5
      frame(0x005, "00 00 01"),                 // SampleTime of 3 bytes
      frame(0x006, "00 00 01"),                 // GroupCounter of 3 bytes
  };
  for (std::size_t k = 0; k < bad.size(); ++k) {
    const CanDecoded r = decode({bad[k], frame(0x021, "7F FF 00 00 00 00 00 00")});
    EXPECT_EQ(r.counters.malformed, 1u) << k;
    EXPECT_EQ(r.counters.skipped_bytes, bad[k].len) << k;
    ASSERT_EQ(r.samples.size(), 1u) << k;
    EXPECT_EQ(r.samples[0].flags, 0u) << k;
  }
}

TEST(XsensCanDecoder, ConfiguredIdentifiersAndFormat) {
  OptionMap o;
  o["xsens_id_format"] = std::string("extended");
  o["xsens_quaternion_id"] = std::string("0x18FF0021");
  o["xsens_sample_time_id"] = std::string("0x18FF0005");
  o["xsens_group_counter_id"] = std::string("0x18FF0006");
  const std::vector<CanFrame> stream = {frame(0x18FF0005, "00 00 00 0A", true), frame(0x18FF0021, "7F FF 00 00 00 00 00 00", true),
                                        frame(0x021, "7F FF 00 00 00 00 00 00")};
  const CanDecoded r = decode(stream, o);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 1e-3);
  EXPECT_EQ(r.frame_counters.foreign, 1u);  // the standard 0x021 is not its frame
  auto d = make_xsens_can_decoder(o);
  expect_filters_pass(d->filters(), {stream[0], stream[1]}, {0x021, 0x18FF0021, 0x18FF0022 | CanFrame::kEffFlag});
}

TEST(XsensCanDecoder, OtherFramesChangeNothing) {
  std::mt19937_64 rng(6);
  std::vector<CanFrame> stream;
  for (int k = 0; k < 40; ++k) {
    const auto f = encode_xsens_can(random_unit_quaternion(rng), 100u * k, static_cast<std::uint16_t>(k));
    stream.insert(stream.end(), f.begin(), f.end());
  }
  auto with = make_xsens_can_decoder();
  auto without = make_xsens_can_decoder();
  // Xsens' other outputs (Euler angles 0x022, rate of turn 0x032, error 0x001) are foreign.
  expect_other_frames_change_nothing(*with, *without, stream, {0x022, 0x032, 0x001, 0x021 | CanFrame::kEffFlag});
  expect_filters_pass(with->filters(), stream, {0x022, 0x032, 0x001, 0x021 | CanFrame::kEffFlag, 0x021 | CanFrame::kRtrFlag});
}

TEST(XsensCanDecoder, ResetForgetsPendingTimeAndRollover) {
  auto d = make_xsens_can_decoder();
  Collector c;
  for (const auto& f : encode_xsens_can(Quat::Identity(), 0xFFFFFFFFu, 65535)) d->feed(f, c);
  d->feed(frame(0x005, "00 00 00 07"), c);
  d->reset();
  d->feed(frame(0x021, "7F FF 00 00 00 00 00 00"), c);
  for (const auto& f : encode_xsens_can(Quat::Identity(), 3, 2)) d->feed(f, c);
  ASSERT_EQ(c.samples.size(), 3u);
  EXPECT_EQ(c.samples[1].flags, 0u);
  EXPECT_DOUBLE_EQ(c.samples[2].device_time, 3e-4);
  EXPECT_EQ(c.samples[2].frame_counter, 2u);
}

TEST(XsensCanDecoder, OptionsAreChecked) {
  OptionMap o;
  o["xsens_quaternion_id"] = std::string("0x800");  // above 11 bits
  EXPECT_THROW(make_xsens_can_decoder(o), std::invalid_argument);
  o = {};
  o["xsens_sample_time_id"] = std::string("0x021");  // the same as the quaternion's
  EXPECT_THROW(make_xsens_can_decoder(o), std::invalid_argument);
  o = {};
  o["xsens_sample_time_unit"] = std::string("10us");
  EXPECT_THROW(make_xsens_can_decoder(o), std::invalid_argument);
  EXPECT_EQ(make_can_decoder("xsens-can")->protocol(), "xsens-can");
}

// 10 MB of random frames with its three identifiers: no checksum in the payload (the bus's CRC
// protects frames), so quaternion frames are accepted at the rate a random point of [-1, 1]^4
// lies within 1e-3 of the unit sphere; every sample a unit quaternion.
TEST(XsensCanDecoder, RandomFramesAreAcceptedAtTheGeometricRate) {
  std::mt19937_64 rng(99);
  const std::vector<CanFrame> frames = random_frames(2'600'000, {0x005, 0x006, 0x021}, rng);
  ASSERT_GE(payload_bytes(frames), 10'000'000u);
  std::uint64_t candidates = 0;
  for (const auto& f : frames) {
    bool ok = f.id() == 0x021 && f.len == 8;
    for (int k = 0; ok && k < 4; ++k) ok = !(f.data[2 * k] == 0x80 && f.data[2 * k + 1] == 0x00);
    candidates += ok;
  }
  const CanDecoded r = decode(frames);
  const double p = std::numbers::pi * std::numbers::pi / 2.0 * (std::pow(1.001, 4) - std::pow(0.999, 4)) / 16.0;
  expect_binomial_within(r.counters.samples, static_cast<double>(candidates), p);
  expect_unit_quaternions(r.samples);
  EXPECT_EQ(r.counters.bytes, payload_bytes(frames));
  for (const auto& s : r.samples) ASSERT_TRUE(std::isfinite(s.device_time));
}

// 10 MB of random quaternion frames (8 bytes each): accepted at the rate a random point of the
// cube [-1, 1]^4 lies within 1e-3 of the unit sphere, π²/2 · (1.001⁴ − 0.999⁴) / 16 ≈ 0.25%
// (about 3100 of 1.25 million, ± 55): a tolerance 20% wider or narrower would be caught.
TEST(XsensCanDecoder, RandomQuaternionFramesPassTheNormCheckAtTheGeometricRate) {
  std::mt19937_64 rng(101);
  std::vector<CanFrame> frames = random_frames(1'250'000, {0x021}, rng);
  std::uint64_t candidates = 0;  // no component -32768
  for (auto& f : frames) {
    f.len = 8;
    bool ok = true;
    for (int k = 0; ok && k < 4; ++k) ok = !(f.data[2 * k] == 0x80 && f.data[2 * k + 1] == 0x00);
    candidates += ok;
  }
  const CanDecoded r = decode(frames);
  const double p = std::numbers::pi * std::numbers::pi / 2.0 * (std::pow(1.001, 4) - std::pow(0.999, 4)) / 16.0;
  expect_binomial_within(r.counters.samples, static_cast<double>(candidates), p);
  EXPECT_EQ(r.counters.samples + r.counters.malformed, frames.size());
  expect_unit_quaternions(r.samples);
}

}  // namespace
}  // namespace posefair::drivers::xsens_can_decoder_test
