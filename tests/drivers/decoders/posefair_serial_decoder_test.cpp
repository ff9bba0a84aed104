// posefair's serial protocol (docs/protocol.md, "Serial protocol for microcontroller
// trackers"; drivers/src/posefair_serial_decoder.cpp): the document's examples byte for byte,
// round trips of both forms, chunking, resynchronisation, bounds, random bytes, rollover.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "posefair/drivers/checksums.hpp"
#include "posefair/drivers/posefair_serial_decoder.hpp"

namespace posefair::drivers::posefair_serial_decoder_test {
namespace {

using namespace ::posefair::testing;
using Bytes = std::vector<std::uint8_t>;

Bytes text(std::string_view s) { return Bytes(s.begin(), s.end()); }

// "$<body>*HH\r\n" with the right checksum.
Bytes sentence(std::string_view body) {
  const std::uint8_t x = checksum::xor8({reinterpret_cast<const std::uint8_t*>(body.data()), body.size()});
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", x);
  std::string line = "$";
  line.append(body);
  line.append(tail);
  return text(line);
}

// A binary frame with any header and payload, and the right CRC.
Bytes frame(std::uint8_t version, std::uint8_t flags, const Bytes& payload) {
  Bytes f = {0xF5, 0x50, version, flags, static_cast<std::uint8_t>(payload.size())};
  for (std::uint8_t b : payload) f.push_back(b);  // (not insert: GCC 12 warns falsely about it here)
  const std::uint16_t crc = checksum::crc16_ccitt({f.data() + 2, f.size() - 2}, 0xFFFF);
  f.push_back(static_cast<std::uint8_t>(crc));
  f.push_back(static_cast<std::uint8_t>(crc >> 8));
  return f;
}

Bytes le_floats(std::initializer_list<float> vs, std::uint32_t time) {
  Bytes out = {static_cast<std::uint8_t>(time), static_cast<std::uint8_t>(time >> 8), static_cast<std::uint8_t>(time >> 16),
               static_cast<std::uint8_t>(time >> 24)};
  for (float v : vs) {
    const auto u = std::bit_cast<std::uint32_t>(v);
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<std::uint8_t>(u >> (8 * b)));
  }
  return out;
}

std::unique_ptr<Decoder> make() { return make_posefair_serial_decoder(); }

Decoded decode(const Bytes& bytes) { return decode_chunks(make(), bytes); }

Bytes as_bytes(const std::string& s) { return Bytes(s.begin(), s.end()); }

const Quat kExampleQ(0.5, -0.5, 0.5, -0.5);
const Vec3 kExampleP(1, -2, 0.25);

// ---- the document's examples ----

TEST(PosefairSerialDecoder, ProtocolName) { EXPECT_EQ(make_posefair_serial_decoder()->protocol(), "posefair"); }

TEST(PosefairSerialDecoder, CrcIsCcittFalse) {
  const Bytes check = text("123456789");
  EXPECT_EQ(checksum::crc16_ccitt(check, 0xFFFF), 0x29B1);  // the document's check value
}

TEST(PosefairSerialDecoder, DocumentExamplesByteForByte) {
  EXPECT_EQ(encode_posefair_sentence(1234567, kExampleQ, &kExampleP), "$PFQ,1234567,0.5,-0.5,0.5,-0.5,1,-2,0.25*40\r\n");
  EXPECT_EQ(encode_posefair_sentence(4294967295u, Quat::Identity(), nullptr), "$PFQ,4294967295,1,0,0,0*67\r\n");
  EXPECT_EQ(encode_posefair_frame(1234567, kExampleQ, &kExampleP),
            hex("f5 50 01 01 20 87 d6 12  00 00 00 00 3f 00 00 00"
                "bf 00 00 00 3f 00 00 00  bf 00 00 80 3f 00 00 00"
                "c0 00 00 80 3e dc 35"));
  EXPECT_EQ(encode_posefair_frame(4294967295u, Quat::Identity(), nullptr),
            hex("f5 50 01 00 14 ff ff ff ff 00 00 80 3f 00 00 00 00 00 00 00 00 00 00 00 00 c8 54"));
}

TEST(PosefairSerialDecoder, DocumentExamplesDecode) {
  const Decoded r = decode(cat({text("$PFQ,1234567,0.5,-0.5,0.5,-0.5,1,-2,0.25*40\r\n"),
                                hex("f5 50 01 01 20 87 d6 12 00 00 00 00 3f 00 00 00 bf 00 00 00 3f 00 00 00 bf 00 00 80 "
                                    "3f 00 00 00 c0 00 00 80 3e dc 35"),
                                text("$PFQ,4294967295,1,0,0,0*67\r\n")}));
  ASSERT_EQ(r.samples.size(), 3u);
  for (int k = 0; k < 2; ++k) {
    const DecodedSample& s = r.samples[k];
    EXPECT_EQ(s.orientation.coeffs(), kExampleQ.coeffs()) << k;
    EXPECT_EQ(s.position, kExampleP) << k;
    EXPECT_EQ(s.flags, kHasPosition | kHasDeviceTime) << k;
    EXPECT_DOUBLE_EQ(s.device_time, 1.234567) << k;
    EXPECT_FALSE(s.has_frame_counter);
  }
  EXPECT_EQ(r.samples[2].orientation.coeffs(), Quat::Identity().coeffs());
  EXPECT_EQ(r.samples[2].flags, kHasDeviceTime);
  EXPECT_DOUBLE_EQ(r.samples[2].device_time, 4294.967295);
  EXPECT_EQ(r.counters.frames, 3u);
  EXPECT_EQ(r.counters.skipped_bytes, 0u);
  EXPECT_EQ(r.counters.resyncs, 0u);
}

TEST(PosefairSerialDecoder, LowerCaseChecksumAndBareLineFeedAccepted) {
  const Decoded r = decode(cat({text("$PFQ,5,0.7071068,0,0,0.7071068*5e\r\n"), text("$PFQ,6,1,0,0,0*5C\n")}));
  EXPECT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.counters.bad_checksum, 0u);
  EXPECT_EQ(r.counters.skipped_bytes, 0u);
}

// ---- round trips ----

TEST(PosefairSerialDecoder, RoundTripsBothFormsInterleaved) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> pos(-5.0, 5.0);
  std::uniform_int_distribution<std::uint32_t> step(1, 50000);
  Bytes stream;
  struct Sent {
    Quat q;
    Vec3 p;
    bool has_p;
    bool binary;
    std::uint32_t t;
  };
  std::vector<Sent> sent;
  std::uint32_t t = 0xFF000000u;  // wraps during the run
  for (int k = 0; k < 1000; ++k) {
    Sent s{random_unit_quaternion(rng), Vec3(pos(rng), pos(rng), pos(rng)), (k % 3) != 0, (k % 2) != 0, t};
    const Bytes b = s.binary ? encode_posefair_frame(t, s.q, s.has_p ? &s.p : nullptr)
                             : as_bytes(encode_posefair_sentence(t, s.q, s.has_p ? &s.p : nullptr));
    stream = cat({stream, b});
    sent.push_back(s);
    t += step(rng) * 1000;
  }
  const Decoded r = decode(stream);
  ASSERT_EQ(r.samples.size(), sent.size());
  EXPECT_EQ(r.counters.frames, sent.size());
  EXPECT_EQ(r.counters.skipped_bytes, 0u);
  double previous_time = -1.0;
  for (std::size_t k = 0; k < sent.size(); ++k) {
    const DecodedSample& s = r.samples[k];
    const Sent& e = sent[k];
    if (e.binary) {  // float32 on the wire
      EXPECT_LT((s.orientation.coeffs() - e.q.coeffs()).cwiseAbs().maxCoeff(), 2e-7) << k;
      if (e.has_p) {
        EXPECT_LT((s.position - e.p).cwiseAbs().maxCoeff(), 5e-7) << k;
      }
    } else {  // shortest round-trip text: exact
      EXPECT_EQ(s.orientation.coeffs(), e.q.coeffs()) << k;
      if (e.has_p) {
        EXPECT_EQ(s.position, e.p) << k;
      }
    }
    EXPECT_NEAR(s.orientation.norm(), 1.0, 1e-15);
    EXPECT_EQ(s.flags, e.has_p ? kHasPosition | kHasDeviceTime : std::uint32_t{kHasDeviceTime}) << k;
    if (!e.has_p) {
      EXPECT_EQ(s.position, Vec3::Zero());
    }
    EXPECT_GT(s.device_time, previous_time) << k;
    previous_time = s.device_time;
    // Unwrapped: the raw time plus whole periods.
    const double periods = (s.device_time * 1e6 - e.t) / 4294967296.0;
    EXPECT_NEAR(periods, std::round(periods), 1e-6) << k;
  }
  EXPECT_GT(previous_time, 4294.967296);  // it wrapped
}

TEST(PosefairSerialDecoder, DeviceTimeRollsOverInBothForms) {
  const Quat q = Quat::Identity();
  const Decoded r = decode(cat({as_bytes(encode_posefair_sentence(4294967290u, q, nullptr)),
                                encode_posefair_frame(4294967295u, q, nullptr), as_bytes(encode_posefair_sentence(4, q, nullptr)),
                                encode_posefair_frame(10, q, nullptr), encode_posefair_frame(4294967000u, q, nullptr),
                                as_bytes(encode_posefair_sentence(3, q, nullptr))}));
  ASSERT_EQ(r.samples.size(), 6u);
  const double p = 4294967296.0;
  const double expected_us[] = {4294967290.0, 4294967295.0, p + 4, p + 10, p + 4294967000.0, 2 * p + 3};
  for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(r.samples[k].device_time, expected_us[k] * 1e-6) << k;
}

TEST(PosefairSerialDecoder, ResetForgetsPartialFrameAndRollover) {
  auto d = make_posefair_serial_decoder();
  Collector c;
  d->feed(as_bytes(encode_posefair_sentence(4294967295u, Quat::Identity(), nullptr)), c);
  const Bytes f = encode_posefair_frame(7, Quat::Identity(), nullptr);
  d->feed({f.data(), 10}, c);
  d->reset();
  d->feed(encode_posefair_frame(1, Quat::Identity(), nullptr), c);
  ASSERT_EQ(c.samples.size(), 2u);
  EXPECT_DOUBLE_EQ(c.samples[1].device_time, 1e-6);  // not 2^32 + 1 µs
  EXPECT_EQ(d->counters().bad_checksum, 0u);
}

// ---- what a valid frame may not contain ----

TEST(PosefairSerialDecoder, ImpossibleContentsAreMalformed) {
  const std::vector<std::string> bodies = {
      "PFQ,1,2,0,0,0",                      // norm 2
      "PFQ,1,0,0,0,0",                      // zero
      "PFQ,1,0.99,0,0,0",                   // norm 0.99
      "PFQ,1,nan,0,0,0",                    // NaN
      "PFQ,1,inf,0,0,0",                    // infinity
      "PFQ,1,1e999,0,0,0",                  // beyond the double range
      "PFQ,1,1,0,0,0,1,2,inf",              // position not finite
      "PFQ,1,1,0,0",                        // 4 fields
      "PFQ,1,1,0,0,0,1",                    // 6 fields
      "PFQ,1,1,0,0,0,1,2,3,4",              // 9 fields
      "PFQ,1,1,0,0,0,1,2,3,4,5,6,7,8",      // many fields
      "PFQ,4294967296,1,0,0,0",             // time beyond u32
      "PFQ,-1,1,0,0,0",                     // negative time
      "PFQ,1.5,1,0,0,0",                    // fractional time
      "PFQ,,1,0,0,0",                       // empty time
      "PFQ,1,,0,0,0",                       // empty number
      "PFQ,1,+1,0,0,0",                     // '+'
      "PFQ,1, 1,0,0,0",                     // space
      "PFQ,1,0x1,0,0,0",                    // hexadecimal
      "PFQ,1,1,0,0,0,",                     // trailing comma
      "PFQ",                                // no fields
  };
  for (const std::string& body : bodies) {
    const Decoded r = decode(cat({sentence(body), as_bytes(encode_posefair_sentence(9, Quat::Identity(), nullptr))}));
    EXPECT_EQ(r.counters.frames, 2u) << body;
    EXPECT_EQ(r.counters.malformed, 1u) << body;
    EXPECT_EQ(r.counters.bad_checksum, 0u) << body;
    ASSERT_EQ(r.samples.size(), 1u) << body;  // the next sentence decodes
  }
  const std::vector<Bytes> frames = {
      frame(1, 0, le_floats({2, 0, 0, 0}, 1)),                     // norm 2
      frame(1, 0, le_floats({NAN, 0, 0, 0}, 1)),                   // NaN
      frame(1, 0, le_floats({INFINITY, 0, 0, 0}, 1)),              // infinity
      frame(1, 1, le_floats({1, 0, 0, 0, 1, NAN, 0}, 1)),          // position NaN
      frame(1, 1, le_floats({1, 0, 0, 0}, 1)),                     // flag without position
      frame(1, 0, le_floats({1, 0, 0, 0, 1, 2, 3}, 1)),            // position without flag
      frame(1, 2, le_floats({1, 0, 0, 0}, 1)),                     // reserved flag
      frame(1, 0x81, le_floats({1, 0, 0, 0, 1, 2, 3}, 1)),         // reserved flag
      frame(1, 0, Bytes(19, 0)),                                   // short payload
  };
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Decoded r = decode(cat({frames[k], encode_posefair_frame(9, Quat::Identity(), nullptr)}));
    EXPECT_EQ(r.counters.frames, 2u) << k;
    EXPECT_EQ(r.counters.malformed, 1u) << k;
    ASSERT_EQ(r.samples.size(), 1u) << k;
  }
  // Within the tolerance: accepted and normalised.
  const Decoded ok = decode(sentence("PFQ,1,1.0009,0,0,0"));
  ASSERT_EQ(ok.samples.size(), 1u);
  EXPECT_EQ(ok.samples[0].orientation.w(), 1.0);
}

// docs/protocol.md, "Raw IMU": the raw-IMU examples byte for byte (bytes and checksums computed
// there independently of the encoders) and what they decode to.
TEST(PosefairSerialDecoder, RawImuDocumentExamples) {
  const Vec3 gyro(0.5, -0.25, 0.125), accel(0.5, -1, 9.8125), mag(20, -5, -40);
  const std::string pfi = "$PFI,1234567,0.5,-0.25,0.125,0.5,-1,9.8125,20,-5,-40*45\r\n";
  EXPECT_EQ(encode_posefair_imu_sentence(1234567, gyro, accel, &mag), pfi);
  const Bytes raw_only = hex(
      "f5 50 01 0e 28 87 d6 12 00 00 00 00 3f 00 00 80"
      "be 00 00 00 3e 00 00 00 3f 00 00 80 bf 00 00 1d"
      "41 00 00 a0 41 00 00 a0 c0 00 00 20 c2 34 6c");
  const PosefairImuReading imu{gyro, accel};
  EXPECT_EQ(encode_posefair_frame(1234567, nullptr, nullptr, &imu, &mag), raw_only);
  const Bytes with_q = hex(
      "f5 50 01 02 2c ff ff ff ff 00 00 80 3f 00 00 00"
      "00 00 00 00 00 00 00 00 00 00 00 00 3f 00 00 80"
      "be 00 00 00 3e 00 00 00 3f 00 00 80 bf 00 00 1d"
      "41 95 17");
  const Quat identity = Quat::Identity();
  EXPECT_EQ(encode_posefair_frame(4294967295u, &identity, nullptr, &imu, nullptr), with_q);

  const Decoded r = decode(cat({as_bytes(pfi), raw_only, with_q}));
  ASSERT_EQ(r.samples.size(), 3u);
  EXPECT_EQ(r.counters.frames, 3u);
  for (std::size_t k = 0; k < 2; ++k) {
    const DecodedSample& x = r.samples[k];
    EXPECT_EQ(x.flags, kHasDeviceTime | kNoOrientation | kHasGyro | kHasAccel | kHasMag) << k;
    EXPECT_EQ(x.gyro, gyro) << k;
    EXPECT_EQ(x.accel, accel) << k;
    EXPECT_EQ(x.mag, mag) << k;
    EXPECT_DOUBLE_EQ(x.device_time, 1.234567) << k;
  }
  EXPECT_EQ(r.samples[2].flags, kHasDeviceTime | kHasGyro | kHasAccel);
  EXPECT_EQ(r.samples[2].orientation.coeffs(), identity.coeffs());
  EXPECT_EQ(r.samples[2].gyro, gyro);

  // Without the magnetometer, every combination of parts round-trips.
  const Vec3 pos(1, -2, 0.25);
  const Decoded all = decode(cat({as_bytes(encode_posefair_imu_sentence(7, gyro, accel, nullptr)),
                                  encode_posefair_frame(8, &identity, &pos, &imu, &mag),
                                  encode_posefair_frame(9, nullptr, nullptr, nullptr, &mag)}));
  ASSERT_EQ(all.samples.size(), 3u);
  EXPECT_EQ(all.samples[0].flags, kHasDeviceTime | kNoOrientation | kHasGyro | kHasAccel);
  EXPECT_EQ(all.samples[1].flags, kHasDeviceTime | kHasPosition | kHasGyro | kHasAccel | kHasMag);
  EXPECT_EQ(all.samples[1].position, pos);
  EXPECT_EQ(all.samples[1].mag, mag);
  EXPECT_EQ(all.samples[2].flags, kHasDeviceTime | kNoOrientation | kHasMag);
}

TEST(PosefairSerialDecoder, ImpossibleRawImuContentsAreMalformed) {
  for (const char* body : {"PFI,1,0,0,0,0,0", "PFI,1,0,0,0,0,0,9.8,1", "PFI,1,0,0,0,0,0,9.8,1,2,3,4",
                           "PFI,1,nan,0,0,0,0,9.8", "PFI,1,0,0,0,0,0,9.8,1,2,inf", "PFI,,0,0,0,0,0,9.8"}) {
    const Decoded r = decode(cat({sentence(body), as_bytes(encode_posefair_sentence(9, Quat::Identity(), nullptr))}));
    EXPECT_EQ(r.counters.malformed, 1u) << body;
    ASSERT_EQ(r.samples.size(), 1u) << body;
  }
  const std::vector<Bytes> frames = {
      frame(1, 0x08, le_floats({}, 1)),                                         // no orientation and nothing else
      frame(1, 0x09, le_floats({1, 2, 3}, 1)),                                  // no orientation with a position
      frame(1, 0x0A, le_floats({0, 0, 0, 0, 0}, 1)),                            // one number short
      frame(1, 0x0A, le_floats({0, 0, NAN, 0, 0, 9.8f}, 1)),                    // NaN gyro
      frame(1, 0x06, le_floats({1, 0, 0, 0, 0, 0, 0, 0, 0, 9.8f, 1, 2, INFINITY}, 1)),  // infinite mag
      frame(1, 0x12, le_floats({1, 0, 0, 0, 0, 0, 0, 0, 0, 9.8f}, 1)),          // reserved bit 4
  };
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Decoded r = decode(cat({frames[k], encode_posefair_frame(9, Quat::Identity(), nullptr)}));
    EXPECT_EQ(r.counters.malformed, 1u) << k;
    ASSERT_EQ(r.samples.size(), 1u) << k;
  }
}

TEST(PosefairSerialDecoder, OtherSentencesAndVersionsAreIgnored) {
  const Decoded r = decode(cat({sentence("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"),
                                sentence("PFX,1,1,0,0,0"), sentence("PFQX,1,1,0,0,0"), frame(2, 0, Bytes(40, 7)),
                                as_bytes(encode_posefair_sentence(1, Quat::Identity(), nullptr))}));
  EXPECT_EQ(r.counters.frames, 5u);
  EXPECT_EQ(r.counters.ignored_frames, 4u);
  EXPECT_EQ(r.counters.malformed, 0u);
  EXPECT_EQ(r.samples.size(), 1u);
}

// ---- streams: chunking, resynchronisation, bounds ----

struct Stream {
  Bytes bytes;
  std::size_t good_frames = 0;
  std::size_t good_bytes = 0;
};

// Smooth random motion in both forms, with debug text, garbage and corrupted frames.
Stream make_stream(std::uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pct(0, 99);
  std::normal_distribution<double> n(0.0, 0.02);
  Stream s;
  Quat q = Quat::Identity();
  Vec3 p(0.1, 0.2, 0.3);
  std::uint32_t t = 0xFFF00000u;
  for (int k = 0; k < count; ++k) {
    q = (q * Quat(1.0, n(rng), n(rng), n(rng))).normalized();
    p += Vec3(n(rng), n(rng), n(rng));
    t += 10000;
    const bool with_p = pct(rng) < 50;
    Bytes b = pct(rng) < 50 ? encode_posefair_frame(t, q, with_p ? &p : nullptr)
                            : as_bytes(encode_posefair_sentence(t, q, with_p ? &p : nullptr));
    const int roll = pct(rng);
    if (roll < 4) {
      const Bytes debug = text("imu: calibrating...\r\n");
      s.bytes.insert(s.bytes.end(), debug.begin(), debug.end());
    } else if (roll < 8) {
      for (int g = pct(rng) % 16; g > 0; --g) s.bytes.push_back(static_cast<std::uint8_t>(rng()));
    } else if (roll < 12) {
      // One corrupted byte after the start (a sentence keeps its '$'; a frame its first sync).
      b[1 + static_cast<std::size_t>(pct(rng)) % (b.size() - 1)] ^= 0x04;
      s.bytes.insert(s.bytes.end(), b.begin(), b.end());
      continue;
    }
    s.bytes.insert(s.bytes.end(), b.begin(), b.end());
    ++s.good_frames;
    s.good_bytes += b.size();
  }
  return s;
}

TEST(PosefairSerialDecoder, AnySplitGivesTheSameSamplesAndCounters) {
  const Stream s = make_stream(17, 600);
  const Decoded whole = decode(s.bytes);
  EXPECT_EQ(whole.counters.frames, s.good_frames);
  EXPECT_EQ(whole.samples.size(), s.good_frames);
  EXPECT_EQ(whole.counters.bytes - whole.counters.skipped_bytes, s.good_bytes);
  EXPECT_GT(whole.counters.bad_checksum, 0u);
  EXPECT_GT(whole.counters.resyncs, 0u);

  expect_byte_by_byte_same(make, s.bytes, whole);
  expect_seeded_chunkings_same(make, s.bytes, whole, {1, 2, 3}, 131);
  const Stream small = make_stream(4, 40);
  expect_every_split_same(make, small.bytes, decode(small.bytes));
}

TEST(PosefairSerialDecoder, ResyncsAfterGarbageAndDebugText) {
  const Bytes good = as_bytes(encode_posefair_sentence(1, Quat::Identity(), nullptr));
  const Bytes bin = encode_posefair_frame(2, Quat::Identity(), nullptr);
  const Decoded r = decode(cat({text("hello\r\n"), good, {0xF5, 0x00, 0x50}, bin, text("$PF"), bin}));
  EXPECT_EQ(r.samples.size(), 3u);
  EXPECT_EQ(r.counters.skipped_bytes, 7u + 3u + 3u);
  EXPECT_EQ(r.counters.resyncs, 3u);
  EXPECT_EQ(r.counters.bad_checksum, 0u);
}

TEST(PosefairSerialDecoder, BadChecksumsAreCountedAndTheNextFrameDecodes) {
  Bytes bad_text = as_bytes(encode_posefair_sentence(1, Quat::Identity(), nullptr));
  bad_text[5] = '2';  // the time digit
  Bytes bad_bin = encode_posefair_frame(2, Quat::Identity(), nullptr);
  bad_bin[10] ^= 0x01;
  const std::vector<Bytes> no_checksum = {text("$PFQ,3,1,0,0,0\r\n"), text("$PFQ,3,1,0,0,0*5\r\n"),
                                          text("$PFQ,3,1,0,0,0*5G\r\n"), text("$\r\n"), text("$PFQ,3,1,0\r,0,0*58\r\n")};
  Bytes stream = cat({bad_text, bad_bin});
  for (const Bytes& b : no_checksum) stream = cat({stream, b});
  const Bytes good = encode_posefair_frame(5, Quat(0, 1, 0, 0), nullptr);
  const Decoded r = decode(cat({stream, good}));
  EXPECT_EQ(r.counters.bad_checksum, 2u + no_checksum.size());
  EXPECT_EQ(r.counters.frames, 1u);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.samples[0].orientation.coeffs(), Quat(0, 1, 0, 0).coeffs());
  EXPECT_EQ(r.counters.skipped_bytes, stream.size());
  EXPECT_EQ(r.counters.resyncs, 1u);
}

// A frame whose length was corrupted upwards must not swallow what follows it.
TEST(PosefairSerialDecoder, FrameInsideAFalseCandidateIsFound) {
  Bytes bad = encode_posefair_frame(1, Quat::Identity(), nullptr);
  bad[4] = 60;
  const Bytes good = as_bytes(encode_posefair_sentence(2, Quat(0, 0, 1, 0), nullptr));
  Bytes stream = cat({bad, good});
  while (stream.size() < 100) stream.push_back('\n');
  const Decoded r = decode(stream);
  EXPECT_EQ(r.counters.bad_checksum, 1u);
  ASSERT_EQ(r.samples.size(), 1u);
  EXPECT_DOUBLE_EQ(r.samples[0].device_time, 2e-6);
}

TEST(PosefairSerialDecoder, AbsurdLengthDoesNotStall) {
  auto d = make_posefair_serial_decoder();
  Collector c;
  const Bytes good = encode_posefair_frame(3, Quat::Identity(), nullptr);
  d->feed(cat({{0xF5, 0x50, 0x01, 0x00, 0xFF}, good}), c);
  EXPECT_EQ(c.samples.size(), 1u);
  d->feed(cat({{0xF5, 0x50, 0x01, 0x00, 69}, good}), c);
  EXPECT_EQ(c.samples.size(), 2u);
  EXPECT_EQ(d->counters().malformed, 2u);
  // 68 is within the bound: the decoder waits for it.
  d->feed(cat({{0xF5, 0x50, 0x01, 0x00, 68}, good}), c);
  EXPECT_EQ(c.samples.size(), 2u);
  d->feed(Bytes(68, 0x00), c);
  EXPECT_EQ(c.samples.size(), 3u);
  EXPECT_EQ(d->counters().malformed, 2u);
  EXPECT_EQ(d->counters().bad_checksum, 1u);
}

TEST(PosefairSerialDecoder, OverlongSentenceIsDiscardedAndCounted) {
  const Bytes good = as_bytes(encode_posefair_sentence(4, Quat::Identity(), nullptr));
  // 255 bytes from '$' without '\n': malformed, dropped whole; the good sentence right
  // behind decodes.
  Bytes longline = text("$PFQ,1,1,0,0,0");
  longline.resize(255, '0');
  const Decoded r = decode(cat({longline, good}));
  EXPECT_EQ(r.counters.malformed, 1u);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.counters.skipped_bytes, 255u);
  // A valid sentence of exactly 255 bytes is accepted.
  std::string body = "PFQ,4,1,0,0,0,0.";
  body += std::string(249 - body.size() - 4, '0');
  body += ",0,0";
  const Bytes exact = sentence(body);
  ASSERT_EQ(exact.size(), 255u);
  const Decoded e = decode(exact);
  EXPECT_EQ(e.counters.malformed, 0u);
  EXPECT_EQ(e.samples.size(), 1u);
  // One byte more is too long, though it would end in '\n' right after the bound.
  Bytes too_long = exact;
  too_long.insert(too_long.begin() + 20, '0');
  const Decoded t = decode(too_long);
  EXPECT_EQ(t.counters.malformed, 1u);
  EXPECT_EQ(t.samples.size(), 0u);
  // Endless text after '$' without '\n': the first 255 bytes are the overlong sentence, the
  // rest is skipped like any text that does not start with '$'.
  Bytes endless = text("$");
  endless.resize(100000, 'A');
  const Decoded en = decode(cat({endless, good}));
  EXPECT_EQ(en.samples.size(), 1u);
  EXPECT_EQ(en.counters.malformed, 1u);
  EXPECT_EQ(en.counters.skipped_bytes, 100000u);
  EXPECT_EQ(en.counters.resyncs, 1u);
}

TEST(PosefairSerialDecoder, CutSentenceIsAbandonedAtTheNextStart) {
  const Bytes good = as_bytes(encode_posefair_sentence(4, Quat::Identity(), nullptr));
  const Bytes bin = encode_posefair_frame(5, Quat::Identity(), nullptr);
  const Decoded r = decode(cat({text("$PFQ,3,0.1"), good, text("$PFQ,3,0.1"), bin}));
  EXPECT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.counters.bad_checksum, 0u);
  EXPECT_EQ(r.counters.malformed, 0u);
  EXPECT_EQ(r.counters.skipped_bytes, 20u);
}

// 10 MB of seeded random bytes. A binary candidate needs F5 50 and then a 16-bit CRC match
// (2^-16); a sentence needs '$', then "PFQ," and a matching XOR among printable bytes, which
// random bytes essentially never give. No sample may be anything but a finite unit quaternion.
TEST(PosefairSerialDecoder, RandomBytesAcceptedWithinTheChecksumRate) {
  std::mt19937_64 rng(20240602);
  const auto [r, candidates] = decode_random_reads_of_4096(make(), rng, 0xF5, 0x50);
  EXPECT_GT(candidates, 100u);
  expect_poisson_at_most(r.counters.frames, static_cast<double>(candidates) / 65536.0, 1.0);  // mean < 0.01
  EXPECT_GT(r.counters.skipped_bytes, 9'900'000u);
  expect_unit_quaternions(r.samples);
  for (const DecodedSample& s : r.samples) ASSERT_TRUE(s.position.allFinite());
}

}  // namespace
}  // namespace posefair::drivers::posefair_serial_decoder_test
