// The DroneCAN uavcan.equipment.ahrs.Solution decoder (drivers/src/dronecan_ahrs_decoder.cpp):
// float16, the transfer CRC, a transfer framed by hand from the specification, round trips
// through the encoder, lost/duplicated/interleaved frames, timeouts, malformed payloads, nodes,
// and 10 MB of random frames with the CRC's false-accept rate.
//
// Byte-exact examples: no captured ahrs.Solution transfer was found in the DroneCAN documents
// or tools. The transfer in HandFramedTransferDecodes is written out here field by field from
// the DSDL and the specification's framing rules (not by the encoder), with its CRC computed by a
// bit-by-bit CRC-16-CCITT in this file; the CRC's check value 0x29B1 ("123456789") is the
// specification's.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "../../support/can_decoder_testing.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"
#include "posefair/drivers/float16.hpp"

namespace posefair::drivers::dronecan_ahrs_decoder_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;

// CRC-16-CCITT (0x1021, initial 0xFFFF), one bit at a time.
std::uint16_t bitwise_crc(const Bytes& data) {
  std::uint16_t crc = 0xFFFF;
  for (std::uint8_t b : data) {
    crc ^= static_cast<std::uint16_t>(b << 8);
    for (int i = 0; i < 8; ++i) crc = static_cast<std::uint16_t>(crc & 0x8000 ? (crc << 1) ^ 0x1021 : crc << 1);
  }
  return crc;
}

std::uint32_t message_id(std::uint8_t node, std::uint8_t priority = 16) {
  return CanFrame::kEffFlag | (std::uint32_t{priority} << 24) | (1000u << 8) | node;
}

CanDecoded decode(const std::vector<CanFrame>& frames, const OptionMap& o = {}) {
  return decode_frames(make_dronecan_ahrs_decoder(o), frames);
}

std::vector<CanFrame> transfer(const Quat& q, std::uint64_t usec, std::uint8_t node, std::uint8_t tid,
                               std::array<std::uint8_t, 3> cov = {0, 0, 0}, double t = 0.0) {
  return encode_dronecan_transfer(kDroneCanAhrsSolutionId, kDroneCanAhrsSolutionSignature,
                                  serialize_dronecan_ahrs_solution(q, usec, cov), node, tid, 16, t);
}

TEST(Float16, KnownValuesAndEveryHalfRoundTrips) {
  EXPECT_EQ(float_to_half(1.0f), 0x3C00);
  EXPECT_EQ(float_to_half(-2.0f), 0xC000);
  EXPECT_EQ(float_to_half(65504.0f), 0x7BFF);
  EXPECT_EQ(float_to_half(70000.0f), 0x7C00);                // overflow: inf
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -24)), 0x0001);   // smallest subnormal
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -26)), 0x0000);   // underflow
  EXPECT_EQ(float_to_half(1.0f + std::ldexp(1.0f, -11)), 0x3C00);      // tie: to even
  EXPECT_EQ(float_to_half(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3C02);  // tie: to even (up)
  EXPECT_EQ(half_to_float(0x3555), 0.333251953125f);
  EXPECT_EQ(half_to_float(0x0001), std::ldexp(1.0f, -24));
  for (std::uint32_t h = 0; h <= 0xFFFF; ++h) {
    const float f = half_to_float(static_cast<std::uint16_t>(h));
    if (std::isnan(f)) {
      ASSERT_TRUE(std::isnan(half_to_float(float_to_half(f)))) << h;
    } else {
      ASSERT_EQ(float_to_half(f), h) << h;
    }
  }
}

TEST(DroneCanAhrs, TransferCrcIsCcittSeededWithTheSignature) {
  EXPECT_EQ(bitwise_crc(hex("31 32 33 34 35 36 37 38 39")), 0x29B1);
  const Bytes payload = hex("01 02 03 04 05 06 07 08 09 0A");
  Bytes with_signature;
  for (int i = 0; i < 8; ++i) with_signature.push_back(static_cast<std::uint8_t>(kDroneCanAhrsSolutionSignature >> (8 * i)));
  with_signature.insert(with_signature.end(), payload.begin(), payload.end());
  EXPECT_EQ(dronecan_transfer_crc(kDroneCanAhrsSolutionSignature, payload), bitwise_crc(with_signature));
}

// One transfer written out by hand: timestamp 123456789 µs, the identity (x y z w = 0 0 0 1),
// no covariances, angular velocity (0.125, -0.25, 0.5), linear acceleration (0, 0.5, -9.8125),
// from node 42 with transfer id 7: 29 payload bytes + 2 CRC bytes = 31 bytes in 5 frames.
TEST(DroneCanAhrs, HandFramedTransferDecodes) {
  const Bytes payload = hex(
      "15 CD 5B 07 00 00 00"     // uint56 timestamp, little-endian
      "00 00 00 00 00 00 00 3C"  // float16 x, y, z = 0, w = 1.0 (0x3C00)
      "00"                       // void4, orientation_covariance length 0
      "00 30 00 B4 00 38"        // angular velocity 0.125 (0x3000), -0.25 (0xB400), 0.5 (0x3800)
      "00"                       // void4, angular_velocity_covariance length 0
      "00 00 00 38 E8 C8");      // linear acceleration 0, 0.5, -9.8125 (0xC8E8); empty tail array
  ASSERT_EQ(payload.size(), 29u);
  EXPECT_EQ(serialize_dronecan_ahrs_solution(Quat::Identity(), 123456789), payload);

  Bytes crc_input;
  for (int i = 0; i < 8; ++i) crc_input.push_back(static_cast<std::uint8_t>(kDroneCanAhrsSolutionSignature >> (8 * i)));
  crc_input.insert(crc_input.end(), payload.begin(), payload.end());
  const std::uint16_t crc = bitwise_crc(crc_input);
  Bytes all = {static_cast<std::uint8_t>(crc), static_cast<std::uint8_t>(crc >> 8)};
  all.insert(all.end(), payload.begin(), payload.end());
  // Tail bytes: start 0x80, end 0x40, toggle 0x20 (0 in the first frame), transfer id 7.
  const std::uint8_t tails[] = {0x87, 0x27, 0x07, 0x27, 0x47};
  std::vector<CanFrame> frames;
  for (std::size_t k = 0; k < 5; ++k) {
    Bytes d(all.begin() + static_cast<std::ptrdiff_t>(7 * k), all.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(7 * k + 7, all.size())));
    d.push_back(tails[k]);
    CanFrame f = CanFrame::make(0, true, d);
    f.can_id = message_id(42);
    frames.push_back(f);
  }
  ASSERT_EQ(frames.back().len, 4u);
  const std::vector<CanFrame> encoded = encode_dronecan_transfer(kDroneCanAhrsSolutionId, kDroneCanAhrsSolutionSignature, payload, 42, 7);
  ASSERT_EQ(encoded.size(), frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_EQ(encoded[k].can_id, frames[k].can_id) << k;
    ASSERT_EQ(encoded[k].len, frames[k].len) << k;
    EXPECT_TRUE(std::equal(frames[k].data.begin(), frames[k].data.begin() + frames[k].len, encoded[k].data.begin())) << k;
  }
  const CanDecoded r = decode(frames);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].orientation.coeffs(), Quat::Identity().coeffs());
  EXPECT_EQ(r.samples[0].flags, std::uint32_t{kHasDeviceTime | kHasGyro});
  EXPECT_EQ(r.samples[0].gyro, Vec3(0.125, -0.25, 0.5));  // the angular velocity rides along
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 123.456789);
  EXPECT_EQ(r.samples[0].frame_counter, 7u);
  EXPECT_EQ(r.counters.frames, 1u);
  EXPECT_EQ(r.counters.bytes, 36u);  // 31 + 5 tail bytes
}

TEST(DroneCanAhrs, QuaternionOrderIsXyzwAndSensorToWorld) {
  const double h = std::sqrt(0.5);
  const CanDecoded r = decode(transfer(Quat(h, 0, 0, h), 1, 3, 0));
  ASSERT_EQ(r.samples.size(), 1u);
  const Vec3 v = r.samples[0].orientation * Vec3::UnitX();
  EXPECT_NEAR(v.y(), 1.0, 1e-3);
  EXPECT_NEAR(r.samples[0].orientation.w(), h, 1e-3);
}

TEST(DroneCanAhrs, RoundTripsWithEveryCovarianceLayout) {
  std::mt19937_64 rng(8);
  std::vector<CanFrame> stream;
  std::vector<Quat> qs;
  std::size_t k = 0;
  for (std::uint8_t a : {0, 1, 9})
    for (std::uint8_t b : {0, 4, 9})
      for (std::uint8_t c : {0, 3, 9})
        for (int rep = 0; rep < 4; ++rep, ++k) {
          qs.push_back(random_unit_quaternion(rng));
          const auto f = transfer(qs.back(), 1000 * (k + 1), 10, static_cast<std::uint8_t>(k), {a, b, c});
          stream.insert(stream.end(), f.begin(), f.end());
        }
  const CanDecoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), qs.size());
  EXPECT_EQ(r.counters.frames, qs.size());
  EXPECT_EQ(r.counters.malformed + r.counters.bad_checksum + r.counters.skipped_bytes + r.counters.resyncs, 0u);
  for (std::size_t i = 0; i < qs.size(); ++i) {
    const DecodedSample& s = r.samples[i];
    EXPECT_LT((s.orientation.coeffs() - qs[i].coeffs()).cwiseAbs().maxCoeff(), 1e-3) << i;
    EXPECT_NEAR(s.orientation.norm(), 1.0, 1e-15);
    EXPECT_EQ(s.frame_counter, i);  // transfer ids unwrapped past 31
    EXPECT_DOUBLE_EQ(s.device_time, 1e-3 * static_cast<double>(i + 1));
    EXPECT_EQ(s.gyro, Vec3(0.125, -0.25, 0.5)) << i;  // found behind every covariance length
  }
}

TEST(DroneCanAhrs, BadCrcIsCountedAndTheNextTransferDecodes) {
  std::vector<CanFrame> bad = transfer(Quat::Identity(), 5, 10, 1);
  bad[2].data[3] ^= 0x01;
  const auto good = transfer(Quat(0, 1, 0, 0), 6, 10, 2);
  std::vector<CanFrame> stream = bad;
  stream.insert(stream.end(), good.begin(), good.end());
  const CanDecoded r = decode(stream);
  EXPECT_EQ(r.counters.bad_checksum, 1u);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].frame_counter, 2u);
  EXPECT_EQ(r.counters.skipped_bytes, payload_bytes(bad));
}

TEST(DroneCanAhrs, LostDuplicatedAndRestartedFrames) {
  const auto a = transfer(Quat::Identity(), 5, 10, 1);
  const auto b = transfer(Quat(0, 0, 1, 0), 6, 10, 2);
  {  // a middle frame of `a` lost: the next frame's toggle does not match (skipped), the one
     // after fits again, and the CRC catches the gap; `b` decodes
    std::vector<CanFrame> s = {a[0], a[1], a[3], a[4]};
    s.insert(s.end(), b.begin(), b.end());
    const CanDecoded r = decode(s);
    ASSERT_EQ(r.samples.size(), 1u);
    EXPECT_EQ(r.samples[0].frame_counter, 2u);
    EXPECT_EQ(r.counters.resyncs, 1u);
    EXPECT_EQ(r.counters.bad_checksum, 1u);
    EXPECT_EQ(r.counters.bytes - r.counters.skipped_bytes, payload_bytes(b));
  }
  {  // the last frame of `a` lost: `a` is given up when `b` starts
    std::vector<CanFrame> s = {a[0], a[1], a[2], a[3]};
    s.insert(s.end(), b.begin(), b.end());
    const CanDecoded r = decode(s);
    ASSERT_EQ(r.samples.size(), 1u);
    EXPECT_EQ(r.counters.resyncs, 1u);
    EXPECT_EQ(r.counters.bad_checksum, 0u);
  }
  {  // a frame repeated (a redundant interface): skipped, the transfer completes
    std::vector<CanFrame> s = {a[0], a[1], a[1], a[2], a[3], a[4]};
    const CanDecoded r = decode(s);
    ASSERT_EQ(r.samples.size(), 1u);
    EXPECT_EQ(r.counters.skipped_bytes, a[1].len);
  }
  {  // a new start from the same node while `a` is open: `a` is given up
    std::vector<CanFrame> s = {a[0], a[1]};
    s.insert(s.end(), b.begin(), b.end());
    const CanDecoded r = decode(s);
    ASSERT_EQ(r.samples.size(), 1u);
    EXPECT_EQ(r.counters.resyncs, 1u);
    EXPECT_EQ(r.counters.skipped_bytes, a[0].len + a[1].len);
  }
}

TEST(DroneCanAhrs, NodesAreReassembledApartAndCanBeChosen) {
  const auto a = transfer(Quat::Identity(), 5, 10, 1);
  const auto b = transfer(Quat(0, 1, 0, 0), 6, 11, 1);
  std::vector<CanFrame> s;
  for (std::size_t k = 0; k < a.size(); ++k) {
    s.push_back(a[k]);
    s.push_back(b[k]);
  }
  EXPECT_EQ(decode(s).samples.size(), 2u);
  OptionMap o;
  o["dronecan_node_id"] = std::string("11");
  const CanDecoded r = decode(s, o);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_NEAR(std::abs(r.samples[0].orientation.x()), 1.0, 1e-3);
  EXPECT_EQ(r.frame_counters.foreign, a.size());
  auto d = make_dronecan_ahrs_decoder(o);
  expect_filters_pass(d->filters(), b, {a[0].can_id, message_id(11) & ~CanFrame::kEffFlag, (1001u << 8) | 11u | CanFrame::kEffFlag});
  o["dronecan_node_id"] = std::string("0");
  EXPECT_THROW(make_dronecan_ahrs_decoder(o), std::invalid_argument);
  o["dronecan_node_id"] = std::string("128");
  EXPECT_THROW(make_dronecan_ahrs_decoder(o), std::invalid_argument);
}

TEST(DroneCanAhrs, FramesMoreThanTwoSecondsApartEndTheTransfer) {
  std::vector<CanFrame> a = transfer(Quat::Identity(), 5, 10, 1);
  for (std::size_t k = 0; k < a.size(); ++k) a[k].timestamp = k < 3 ? 0.01 * static_cast<double>(k) : 2.5;
  EXPECT_EQ(decode(a).samples.size(), 0u);
  for (std::size_t k = 0; k < a.size(); ++k) a[k].timestamp = 1.9 * static_cast<double>(k);
  EXPECT_EQ(decode(a).samples.size(), 1u);
}

TEST(DroneCanAhrs, ImpossiblePayloadsAreMalformed) {
  const auto framed = [](const Bytes& p) {
    return encode_dronecan_transfer(kDroneCanAhrsSolutionId, kDroneCanAhrsSolutionSignature, p, 10, 1);
  };
  Bytes good = serialize_dronecan_ahrs_solution(Quat::Identity(), 1);
  std::vector<Bytes> bad;
  bad.push_back(Bytes(good.begin(), good.end() - 1));  // odd tail / short
  Bytes cov10 = good;
  cov10[15] = 10;  // covariance length 10
  bad.push_back(cov10);
  Bytes tail10 = good;
  for (int i = 0; i < 10; ++i) tail10.insert(tail10.end(), {0x00, 0x3C});  // 10 tail items
  bad.push_back(tail10);
  Bytes nan = good;
  nan[13] = 0x00, nan[14] = 0x7E;  // w = NaN
  bad.push_back(nan);
  Bytes half = good;
  half[14] = 0x38;  // w = 0.5
  bad.push_back(half);
  bad.push_back(Bytes(10, 0));  // far too short
  for (std::size_t k = 0; k < bad.size(); ++k) {
    const CanDecoded r = decode(framed(bad[k]));
    EXPECT_EQ(r.counters.malformed, 1u) << k;
    EXPECT_EQ(r.counters.frames, 1u) << k;  // its CRC matched
    EXPECT_EQ(r.samples.size(), 0u) << k;
  }
  // A single-frame transfer cannot hold a Solution on classic CAN: malformed.
  EXPECT_EQ(decode(framed(Bytes(5, 0))).counters.malformed, 1u);
  // FD frames and an empty frame are malformed; anonymous, service and other types are foreign.
  CanFrame fd = transfer(Quat::Identity(), 1, 10, 1)[0];
  fd.fd = true;
  CanFrame empty = fd;
  empty.fd = false;
  empty.len = 0;
  const CanDecoded r = decode({fd, empty});
  EXPECT_EQ(r.counters.malformed, 2u);
  CanFrame anonymous = transfer(Quat::Identity(), 1, 10, 1)[0];
  anonymous.can_id = message_id(0);
  CanFrame service = anonymous;
  service.can_id = message_id(10) | 0x80;
  EXPECT_EQ(decode({anonymous, service}).frame_counters.foreign, 2u);
}

TEST(DroneCanAhrs, OtherFramesChangeNothing) {
  std::mt19937_64 rng(12);
  std::vector<CanFrame> stream;
  for (int k = 0; k < 30; ++k) {
    const auto f = transfer(random_unit_quaternion(rng), 100 + k, 20, static_cast<std::uint8_t>(k));
    stream.insert(stream.end(), f.begin(), f.end());
  }
  auto with = make_dronecan_ahrs_decoder();
  auto without = make_dronecan_ahrs_decoder();
  expect_other_frames_change_nothing(*with, *without, stream,
                                     {(1001u << 8) | 20u | CanFrame::kEffFlag, 0x3E8, message_id(20) | 0x80});
}

TEST(DroneCanAhrs, ResetForgetsOpenTransfersAndTransferIds) {
  auto d = make_dronecan_ahrs_decoder();
  Collector c;
  const auto a = transfer(Quat::Identity(), 5, 10, 31);
  for (const auto& f : a) d->feed(f, c);
  d->feed(transfer(Quat::Identity(), 5, 10, 3)[0], c);
  d->reset();
  for (const auto& f : transfer(Quat::Identity(), 5, 10, 2)) d->feed(f, c);
  ASSERT_EQ(c.samples.size(), 2u);
  EXPECT_EQ(c.samples[1].frame_counter, 2u);  // not 34
  EXPECT_EQ(d->counters().resyncs, 0u);
}

// Transfers framed correctly around random payloads of 29..83 bytes: each completed transfer's
// CRC matches by chance with probability 2^-16; random bytes as frames of its identifier: 10 MB,
// no crash, every sample a unit quaternion.
TEST(DroneCanAhrs, RandomPayloadsPassTheCrcAtItsFalseAcceptRate) {
  std::mt19937_64 rng(77);
  auto d = make_dronecan_ahrs_decoder();
  Collector sink;
  std::uniform_int_distribution<std::size_t> length(29, 83);
  std::uint64_t fed = 0;
  std::uint64_t transfers = 0;
  while (fed < 10'000'000) {
    Bytes p(length(rng));
    for (auto& b : p) b = static_cast<std::uint8_t>(rng());
    auto frames = encode_dronecan_transfer(kDroneCanAhrsSolutionId, kDroneCanAhrsSolutionSignature, p, 7, static_cast<std::uint8_t>(transfers), 16);
    frames[0].data[0] = static_cast<std::uint8_t>(rng());  // a random CRC
    frames[0].data[1] = static_cast<std::uint8_t>(rng());
    for (const auto& f : frames) {
      d->feed(f, sink);
      fed += f.len;
    }
    ++transfers;
  }
  const DecoderCounters& k = d->counters();
  EXPECT_EQ(k.bad_checksum + k.frames, transfers);
  expect_poisson_at_most(k.frames, static_cast<double>(transfers) / 65536.0, 3.0);
  EXPECT_LE(k.samples, k.frames);
  expect_unit_quaternions(sink.samples);

  const std::vector<std::uint32_t> ids = {message_id(1), message_id(2), message_id(127)};
  const std::vector<CanFrame> frames = random_frames(2'600'000, ids, rng);
  const CanDecoded r = decode(frames);
  EXPECT_GE(r.counters.bytes, 10'000'000u);
  expect_unit_quaternions(r.samples);
  expect_poisson_at_most(r.counters.samples, static_cast<double>(r.counters.bad_checksum) / 65536.0, 3.0);
}

}  // namespace
}  // namespace posefair::drivers::dronecan_ahrs_decoder_test
