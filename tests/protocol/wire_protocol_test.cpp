// Wire protocol v1, binary encoding: round trips, the golden byte layout of docs/protocol.md,
// every rejection with its error code, and a fuzz loop.
#include "posefair/daemon/wire_protocol.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "posefair/daemon/json_lines.hpp"
#include "protocol_samples.hpp"

namespace posefair::daemon {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// The golden datagram: docs/protocol.md, "Example", byte for byte. Written by hand from the
// specification's table, not produced by the encoder.
PoseMessage golden_message() {
  PoseMessage m;
  m.session = 0x01020304;
  m.stream = 7;
  m.sequence = 0x1122334455667788ULL;
  m.sample_time = 1.5;
  m.send_time = 2.0;
  m.orientation = Quat(0.5, -0.5, 0.5, -0.5);
  m.position = Vec3(1.0, -2.0, 0.25);
  m.flags = kFlagPosition | kFlagClamped;
  return m;
}

const Bytes kGolden = {
    // header
    0x50, 0x46, 0x50, 0x31,                          //  0 magic "PFP1"
    0x01,                                            //  4 version 1
    0x38,                                            //  5 header length 56
    0x05, 0x00,                                      //  6 flags: position | clamped
    0x04, 0x03, 0x02, 0x01,                          //  8 session 0x01020304
    0x07, 0x00, 0x00, 0x00,                          // 12 stream 7
    0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11,  // 16 sequence 0x1122334455667788
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF8, 0x3F,  // 24 sample time 1.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40,  // 32 send time 2.0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // 40 reserved
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // 48 reserved
    // payload
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F,  // 56 q.w  0.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0xBF,  // 64 q.x -0.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F,  // 72 q.y  0.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0xBF,  // 80 q.z -0.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F,  // 88 p.x  1.0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0,  // 96 p.y -2.0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xD0, 0x3F,  // 104 p.z 0.25
};

TEST(WireProtocol, GoldenBytesMatchTheSpecification) {
  ASSERT_EQ(kGolden.size(), 112u);
  const Bytes encoded = encode_binary(golden_message());
  EXPECT_EQ(encoded, kGolden);
  const DecodeResult r = decode_binary(kGolden);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_TRUE(bitwise_equal(r.message, golden_message()));
  EXPECT_EQ(r.encoding, WireEncoding::kBinary);
}

TEST(WireProtocol, GoldenJsonLineMatchesTheSpecification) {
  const std::string expected =
      R"({"v":1,"session":16909060,"stream":7,"seq":1234605616436508552,"t":1.5,"sent":2,)"
      R"("q":[0.5,-0.5,0.5,-0.5],"p":[1,-2,0.25],"flags":["clamped"]})"
      "\n";
  EXPECT_EQ(encode_json(golden_message()), expected);
  const DecodeResult r = decode_json(expected);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_TRUE(bitwise_equal(r.message, golden_message()));
}

TEST(WireProtocol, OffsetsAndSizesAreThoseOfTheSpecification) {
  EXPECT_EQ(kWireHeaderSize, 56u);
  EXPECT_EQ(wire_offset::kFlags, 6u);
  EXPECT_EQ(wire_offset::kSession, 8u);
  EXPECT_EQ(wire_offset::kStream, 12u);
  EXPECT_EQ(wire_offset::kSequence, 16u);
  EXPECT_EQ(wire_offset::kSampleTime, 24u);
  EXPECT_EQ(wire_offset::kSendTime, 32u);
  EXPECT_EQ(wire_offset::kReserved, 40u);
  EXPECT_EQ(payload_size(0), 32u);
  EXPECT_EQ(payload_size(kFlagPosition), 56u);
  EXPECT_EQ(payload_size(kFlagAngularVelocity), 56u);
  EXPECT_EQ(payload_size(kFlagPosition | kFlagAngularVelocity | kFlagClamped | kFlagBridged), 80u);
}

// ---------------------------------------------------------------------------------------------
// Round trips

TEST(WireProtocol, RoundTripIsBitExactForEveryFlagCombination) {
  for (std::uint16_t flags = 0; flags <= kKnownFlags; ++flags) {
    const PoseMessage m = testing::sample_message(flags, 1000 + flags);
    const Bytes d = encode_binary(m);
    ASSERT_EQ(d.size(), encoded_size(m));
    ASSERT_EQ(d.size(), kWireHeaderSize + 32 + (m.position ? 24u : 0u) + (m.angular_velocity ? 24u : 0u));
    EXPECT_EQ(d[6] | (d[7] << 8), flags);
    const DecodeResult r = decode_binary(d);
    ASSERT_TRUE(r.ok()) << "flags " << flags << ": " << to_string(r.error);
    EXPECT_TRUE(bitwise_equal(r.message, m)) << "flags " << flags;
    EXPECT_EQ(encode_binary(r.message), d);
  }
}

TEST(WireProtocol, RoundTripKeepsExtremeValuesBitForBit) {
  PoseMessage m = testing::sample_message(kFlagPosition | kFlagAngularVelocity, 1);
  m.session = 0xFFFFFFFFu;
  m.stream = 0xFFFFFFFFu;
  m.sequence = std::numeric_limits<std::uint64_t>::max();
  m.sample_time = -0.0;
  m.send_time = std::numeric_limits<double>::max();
  m.position = Vec3(std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::max(), 1.0 / 3.0);
  m.angular_velocity = Vec3(-0.0, 1e-300, 0.1);
  const DecodeResult r = decode_binary(encode_binary(m));
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_TRUE(bitwise_equal(r.message, m));
  EXPECT_TRUE(std::signbit(r.message.sample_time));
}

TEST(WireProtocol, PresenceBitsFollowTheOptionalsNotTheFlagsField) {
  PoseMessage m = testing::sample_message(0, 3);
  m.flags = kFlagPosition | kFlagAngularVelocity | kFlagBridged;  // claims both, has neither
  const Bytes d = encode_binary(m);
  EXPECT_EQ(d.size(), 88u);
  EXPECT_EQ(d[6], kFlagBridged);
  m.position = Vec3(1, 2, 3);
  m.flags = 0;
  EXPECT_EQ(encode_binary(m)[6], kFlagPosition);
}

TEST(WireProtocol, EncodeIntoTooSmallBufferThrows) {
  std::vector<std::uint8_t> small(87);
  EXPECT_THROW(encode_binary(testing::sample_message(0, 1), small), std::length_error);
  std::vector<std::uint8_t> exact(88);
  EXPECT_EQ(encode_binary(testing::sample_message(0, 1), exact), 88u);
}

TEST(WireProtocol, LongerHeaderIsSkippedForForwardCompatibility) {
  const PoseMessage m = testing::sample_message(kFlagPosition | kFlagAngularVelocity, 5);
  Bytes d = encode_binary(m);
  // A later v1 sender with a 64-byte header: 8 more header bytes (non-zero) before the payload.
  Bytes longer(d.begin(), d.begin() + 56);
  for (int k = 0; k < 8; ++k) longer.push_back(static_cast<std::uint8_t>(0xA0 + k));
  longer.insert(longer.end(), d.begin() + 56, d.end());
  longer[5] = 64;
  // Reserved bytes are ignored by receivers too.
  longer[40] = 0xFF;
  longer[55] = 0x01;
  const DecodeResult r = decode_binary(longer);
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_TRUE(bitwise_equal(r.message, m));
}

// ---------------------------------------------------------------------------------------------
// Rejections: each with its own code.

Bytes valid_datagram(std::uint16_t flags = kFlagPosition | kFlagAngularVelocity) {
  return encode_binary(testing::sample_message(flags, 42));
}

void set_f64(Bytes& d, std::size_t offset, double v) {
  const auto bits = std::bit_cast<std::uint64_t>(v);
  for (int i = 0; i < 8; ++i) d[offset + i] = static_cast<std::uint8_t>(bits >> (8 * i));
}

DecodeError decode_error(const Bytes& d) { return decode_binary(d).error; }

TEST(WireProtocol, RejectsTooShort) {
  EXPECT_EQ(decode_error({}), DecodeError::kTooShort);
  EXPECT_EQ(decode_error({0x50, 0x46, 0x50}), DecodeError::kTooShort);
  EXPECT_EQ(decode_error({0x50, 0x46, 0x50, 0x31}), DecodeError::kTooShort);  // magic, nothing else
  const Bytes d = valid_datagram();
  for (std::size_t n : {5u, 8u, 40u, 55u}) EXPECT_EQ(decode_error(Bytes(d.begin(), d.begin() + n)), DecodeError::kTooShort) << n;
}

TEST(WireProtocol, RejectsOversized) {
  Bytes d = valid_datagram();
  d.resize(kMaxDatagramSize + 1, 0);
  EXPECT_EQ(decode_error(d), DecodeError::kOversized);
  d.resize(65507, 0);
  EXPECT_EQ(decode_error(d), DecodeError::kOversized);
  // Exactly 1500 bytes is not oversized (here: a length mismatch).
  d.resize(kMaxDatagramSize);
  EXPECT_EQ(decode_error(d), DecodeError::kLengthMismatch);
  Bytes json(kMaxDatagramSize + 1, ' ');
  json[0] = '{';
  EXPECT_EQ(decode_datagram(json).error, DecodeError::kOversized);
}

TEST(WireProtocol, RejectsBadMagic) {
  for (std::size_t i = 0; i < 4; ++i) {
    Bytes d = valid_datagram();
    d[i] ^= 0x20;  // "pFP1", "PfP1", …
    EXPECT_EQ(decode_error(d), DecodeError::kBadMagic) << i;
  }
  EXPECT_EQ(decode_error({'G', 'E', 'T', ' ', '/'}), DecodeError::kBadMagic);
}

TEST(WireProtocol, RejectsUnsupportedVersion) {
  for (std::uint8_t v : {0, 2, 255}) {
    Bytes d = valid_datagram();
    d[4] = v;
    EXPECT_EQ(decode_error(d), DecodeError::kUnsupportedVersion) << int(v);
  }
}

TEST(WireProtocol, RejectsHeaderLengthBelow56) {
  for (std::uint8_t h : {0, 8, 55}) {
    Bytes d = valid_datagram();
    d[5] = h;
    EXPECT_EQ(decode_error(d), DecodeError::kBadHeaderLength) << int(h);
  }
}

TEST(WireProtocol, RejectsLengthMismatch) {
  Bytes d = valid_datagram();
  d.push_back(0);
  EXPECT_EQ(decode_error(d), DecodeError::kLengthMismatch);
  d.resize(d.size() - 2);
  EXPECT_EQ(decode_error(d), DecodeError::kLengthMismatch);
  Bytes no_pos = valid_datagram(0);
  no_pos[6] = kFlagPosition;  // claims a position that is not there
  EXPECT_EQ(decode_error(no_pos), DecodeError::kLengthMismatch);
  Bytes longer_header = valid_datagram();
  longer_header[5] = 64;  // says 64, is 56
  EXPECT_EQ(decode_error(longer_header), DecodeError::kLengthMismatch);
  Bytes huge_header = valid_datagram();
  huge_header[5] = 255;
  EXPECT_EQ(decode_error(huge_header), DecodeError::kLengthMismatch);
}

TEST(WireProtocol, RejectsUnknownFlagBits) {
  for (int bit = 4; bit < 16; ++bit) {
    Bytes d = valid_datagram();
    const auto flags = static_cast<std::uint16_t>((d[6] | (d[7] << 8)) | (1u << bit));
    d[6] = static_cast<std::uint8_t>(flags);
    d[7] = static_cast<std::uint8_t>(flags >> 8);
    EXPECT_EQ(decode_error(d), DecodeError::kUnknownFlags) << bit;
  }
}

TEST(WireProtocol, RejectsNonFiniteNumbersInEveryField) {
  // Every f64 of a datagram with position and angular velocity: times, q, p, ω.
  const std::vector<std::size_t> offsets = {24, 32, 56, 64, 72, 80, 88, 96, 104, 112, 120, 128};
  for (std::size_t off : offsets) {
    for (double bad : {kNaN, kInf, -kInf}) {
      Bytes d = valid_datagram();
      ASSERT_EQ(d.size(), 136u);
      set_f64(d, off, bad);
      EXPECT_EQ(decode_error(d), DecodeError::kNonFinite) << "offset " << off << " value " << bad;
    }
  }
}

TEST(WireProtocol, RejectsZeroAndNonUnitQuaternions) {
  auto with_q = [](double w, double x, double y, double z) {
    Bytes d = valid_datagram(0);
    set_f64(d, 56, w);
    set_f64(d, 64, x);
    set_f64(d, 72, y);
    set_f64(d, 80, z);
    return decode_error(d);
  };
  EXPECT_EQ(with_q(0, 0, 0, 0), DecodeError::kBadQuaternion);
  EXPECT_EQ(with_q(1.01, 0, 0, 0), DecodeError::kBadQuaternion);
  EXPECT_EQ(with_q(0.998, 0, 0, 0), DecodeError::kBadQuaternion);
  EXPECT_EQ(with_q(1e200, 1e200, 0, 0), DecodeError::kBadQuaternion);  // norm overflows
  EXPECT_EQ(with_q(1 + 1.5e-3, 0, 0, 0), DecodeError::kBadQuaternion);
  // Within the tolerance, and -q, are accepted as sent (not renormalised).
  EXPECT_EQ(with_q(1 + 0.9e-3, 0, 0, 0), DecodeError::kNone);
  EXPECT_EQ(with_q(0, 0, -0.6, -0.8), DecodeError::kNone);
}

TEST(WireProtocol, ErrorCodesHaveDistinctStableNames) {
  std::set<std::string> names;
  for (std::size_t e = 0; e < kDecodeErrorCount; ++e) names.insert(std::string(to_string(static_cast<DecodeError>(e))));
  EXPECT_EQ(names.size(), kDecodeErrorCount);
  EXPECT_EQ(to_string(DecodeError::kTooShort), "too-short");
  EXPECT_EQ(to_string(DecodeError::kUnsupportedVersion), "bad-version");
  EXPECT_EQ(to_string(DecodeError::kJsonSchema), "json-schema");
}

TEST(WireProtocol, ValidateAgreesWithTheDecoder) {
  PoseMessage m = testing::sample_message(kFlagClamped, 9);
  EXPECT_EQ(validate(m), DecodeError::kNone);
  m.flags |= 0x100;
  EXPECT_EQ(validate(m), DecodeError::kUnknownFlags);
  EXPECT_EQ(decode_binary(encode_binary(m)).error, DecodeError::kUnknownFlags);
  m.flags = 0;
  m.position = Vec3(0, kNaN, 0);
  EXPECT_EQ(validate(m), DecodeError::kNonFinite);
  EXPECT_EQ(decode_binary(encode_binary(m)).error, DecodeError::kNonFinite);
  m.position.reset();
  m.orientation = Quat(2, 0, 0, 0);
  EXPECT_EQ(validate(m), DecodeError::kBadQuaternion);
  EXPECT_EQ(decode_binary(encode_binary(m)).error, DecodeError::kBadQuaternion);
}

TEST(WireProtocol, DecodeDatagramDispatchesOnTheFirstByte) {
  const PoseMessage m = testing::sample_message(kFlagPosition, 77);
  const DecodeResult b = decode_datagram(encode_binary(m));
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b.encoding, WireEncoding::kBinary);
  const std::string j = encode_json(m);
  const DecodeResult r = decode_datagram(std::span(reinterpret_cast<const std::uint8_t*>(j.data()), j.size()));
  ASSERT_TRUE(r.ok()) << to_string(r.error);
  EXPECT_EQ(r.encoding, WireEncoding::kJson);
  EXPECT_TRUE(bitwise_equal(r.message, m));
  const std::string not_json = "[1,2]";
  EXPECT_EQ(decode_datagram(std::span(reinterpret_cast<const std::uint8_t*>(not_json.data()), not_json.size())).error,
            DecodeError::kBadMagic);
}

// ---------------------------------------------------------------------------------------------
// Fuzz: random and mutated datagrams. Each one is decoded from a heap buffer of exactly its
// size, so under ASan any read past the end is caught. Accepted datagrams must satisfy the
// specification's invariants.

void check_invariants(const Bytes& d, const DecodeResult& r) {
  if (!r.ok()) return;
  ASSERT_EQ(validate(r.message), DecodeError::kNone);
  ASSERT_LE(d.size(), kMaxDatagramSize);
  if (r.encoding == WireEncoding::kBinary) {
    ASSERT_EQ(d.size(), d[5] + payload_size(r.message.flags));
    // Re-encoding gives the same pose (the bytes too, if the header was a plain 56-byte one).
    const Bytes again = encode_binary(r.message);
    ASSERT_TRUE(bitwise_equal(decode_binary(again).message, r.message));
    bool plain = d[5] == 56;
    for (std::size_t i = 40; i < 56 && plain; ++i) plain = d[i] == 0;
    if (plain) {
      ASSERT_EQ(again, d);
    }
  } else {
    const std::string j = encode_json(r.message);
    ASSERT_TRUE(bitwise_equal(decode_json(j).message, r.message));
  }
}

TEST(WireProtocol, FuzzHundredThousandRandomAndMutatedDatagrams) {
  std::mt19937_64 rng(20240611);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<Bytes> seeds;
  for (std::uint16_t f = 0; f <= kKnownFlags; ++f) seeds.push_back(encode_binary(testing::sample_message(f, f)));
  for (std::uint16_t f = 0; f <= kKnownFlags; ++f) {
    const std::string j = encode_json(testing::sample_message(f, 100 + f));
    seeds.emplace_back(j.begin(), j.end());
  }
  std::size_t accepted = 0;
  std::vector<std::size_t> per_error(kDecodeErrorCount, 0);
  constexpr int kIterations = 100000;
  for (int it = 0; it < kIterations; ++it) {
    Bytes d;
    const int mode = static_cast<int>(rng() % 8);
    if (mode == 0) {  // pure noise of any size up to beyond the limit
      d.resize(rng() % 1600);
      for (auto& b : d) b = static_cast<std::uint8_t>(byte(rng));
    } else {
      d = seeds[rng() % seeds.size()];
      const int mutations = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < mutations; ++k) {
        switch (rng() % 6) {
          case 0:  // flip a bit
            if (!d.empty()) d[rng() % d.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
            break;
          case 1:  // overwrite a byte
            if (!d.empty()) d[rng() % d.size()] = static_cast<std::uint8_t>(byte(rng));
            break;
          case 2:  // truncate
            d.resize(rng() % (d.size() + 1));
            break;
          case 3:  // extend
            for (int n = static_cast<int>(rng() % 40); n > 0; --n) d.push_back(static_cast<std::uint8_t>(byte(rng)));
            break;
          case 4:  // header length field
            if (d.size() > 5 && d[0] != '{') d[5] = static_cast<std::uint8_t>(byte(rng));
            break;
          case 5:  // insert or delete in the middle (shifts JSON tokens and binary fields)
            if (!d.empty()) {
              const auto at = d.begin() + static_cast<std::ptrdiff_t>(rng() % d.size());
              if (rng() % 2)
                d.erase(at);
              else
                d.insert(at, static_cast<std::uint8_t>("{}[],:\"0-e.\\ "[rng() % 14]));
            }
            break;
        }
      }
    }
    // Exactly-sized heap copy: no slack for an over-read to hide in.
    auto exact = std::make_unique<std::uint8_t[]>(d.size() + (d.empty() ? 1 : 0));
    if (!d.empty()) std::memcpy(exact.get(), d.data(), d.size());
    const DecodeResult r = decode_datagram(std::span<const std::uint8_t>(exact.get(), d.size()));
    ASSERT_NO_FATAL_FAILURE(check_invariants(d, r));
    if (r.ok())
      ++accepted;
    else
      ++per_error[static_cast<std::size_t>(r.error)];
  }
  // The loop must have exercised both outcomes and most rejection paths.
  std::printf("fuzz: %zu accepted", accepted);
  std::size_t distinct_errors = 0;
  for (std::size_t e = 1; e < kDecodeErrorCount; ++e) {
    distinct_errors += per_error[e] > 0;
    std::printf(", %s %zu", std::string(to_string(static_cast<DecodeError>(e))).c_str(), per_error[e]);
  }
  std::printf("\n");
  EXPECT_GT(accepted, 1000u);
  EXPECT_GE(distinct_errors, 10u);
}

}  // namespace
}  // namespace posefair::daemon
