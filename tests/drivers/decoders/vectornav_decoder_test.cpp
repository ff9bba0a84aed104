// VectorNav ASCII decoder: the manuals' example sentences, the attitude conventions (checked
// independently of the decoder's own Euler code), encode→decode round trips, chunking, resync,
// bad and disabled checksums, over-long sentences, malformed contents and random input.
//
// Vendor examples used byte for byte (checksums as printed in the documents; all verify):
//  - VN-100 User Manual UM001 rev 2.22, §7.2 register example responses (also in the VersaSync
//    User Manual appendix 5.3.4): register 8 (yaw/pitch/roll) "...*66", 9 (quaternion) "...*4F",
//    15 (quaternion, mag, accel, rate) "...*65", 27 (yaw/pitch/roll, mag, accel, rate) "...*4F".
//  - VN-200 User Manual UM004: §5.11.1 "$VNYPR,+010.071,+000.278,-002.026*60" and the same with
//    the SerialCount field, "...,T1162704*2F"; §5.11 "$VNRRG,30,2,0,0,0,1,0,1*6E"; §5.11.7
//    "$VNERR,03*72"; §3.1 "$VNRRG,11*73".
// No example sentence with a 16-bit CRC was found in the documents; the CRC variant is checked
// against the CRC-16/XMODEM catalogue check value instead. The async forms of the register
// examples ("$VNQMR,<register 15 payload>*44" etc.: the manual says the register's data "will be
// sent out with the $VNQMR header") carry checksums computed for this test, not printed ones.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "../../support/decoder_testing.hpp"
#include "../../support/test_files.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/vectornav_decoder.hpp"

namespace posefair::drivers::vectornav_decoder_test {
namespace {

using namespace ::posefair::testing;
constexpr double kDeg = std::numbers::pi / 180.0;

std::span<const std::uint8_t> bytes_of(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// Feeds `stream` cut at the given chunk sizes (the rest as one last chunk).
Decoded decode(std::string_view stream, const std::vector<std::size_t>& chunks = {}, const OptionMap& options = {}) {
  return decode_chunks(make_vectornav_decoder(options), bytes_of(stream), chunks);
}

Decoded decode_with(std::string_view stream, const OptionMap& options) { return decode(stream, {}, options); }

double angle(const Quat& a, const Quat& b) { return so3::rotation_angle(a, b); }

Quat only_sample(const Decoded& r) {
  EXPECT_EQ(r.samples.size(), 1u);
  return r.samples.empty() ? Quat(0, 0, 0, 0) : r.samples.front().orientation;
}

// The manual's register examples, as printed (UM001 §7.2).
const std::string kReg8 = "$VNRRG,8,+006.271,+000.031,-002.000*66\r\n";
const std::string kReg9 = "$VNRRG,9,-0.017386,-0.000303,+0.055490,+0.998308*4F\r\n";
const std::string kReg15 =
    "$VNRRG,15,-0.017057,-0.000767,+0.056534,+0.998255,+1.0670,-0.2568,+3.0696,-00.019,+00.320,-09.802,-0.002801,"
    "-0.001186,-0.001582*65\r\n";
const std::string kReg27 =
    "$VNRRG,27,+006.380,+000.023,-001.953,+1.0640,-0.2531,+3.0614,+00.005,+00.344,-09.758,-0.001222,-0.000450,"
    "-0.001218*4F\r\n";
// Their payloads under the async headers (checksums computed for this test).
const std::string kYpr8 = "$VNYPR,+006.271,+000.031,-002.000*6E\r\n";
const std::string kQtn9 = "$VNQTN,-0.017386,-0.000303,+0.055490,+0.998308*56\r\n";
const std::string kQmr15 =
    "$VNQMR,-0.017057,-0.000767,+0.056534,+0.998255,+1.0670,-0.2568,+3.0696,-00.019,+00.320,-09.802,-0.002801,"
    "-0.001186,-0.001582*44\r\n";
const std::string kYmr27 =
    "$VNYMR,+006.380,+000.023,-001.953,+1.0640,-0.2531,+3.0614,+00.005,+00.344,-09.758,-0.001222,-0.000450,"
    "-0.001218*67\r\n";

TEST(VectorNavDecoder, ProtocolName) { EXPECT_EQ(make_vectornav_decoder({})->protocol(), "vectornav"); }

TEST(VectorNavDecoder, VendorRegisterResponsesAndErrorsAreValidFramesWithoutSamples) {
  const std::string stream = kReg8 + kReg9 + kReg15 + kReg27 + "$VNRRG,30,2,0,0,0,1,0,1*6E\r\n" + "$VNERR,03*72\r\n" +
                             "$VNRRG,11*73\r\n";
  const Decoded r = decode(stream);
  EXPECT_EQ(r.counters.frames, 7u);  // every printed checksum verifies
  EXPECT_EQ(r.counters.ignored_frames, 7u);
  EXPECT_EQ(r.counters.bad_checksum, 0u);
  EXPECT_EQ(r.counters.skipped_bytes, 0u);
  EXPECT_TRUE(r.samples.empty());
}

TEST(VectorNavDecoder, VendorAsyncYprSentenceDecodesToItsAngles) {
  // UM004 §5.11.1, byte for byte; then with the SerialCount field the device appends.
  const Quat expected = zyx(10.071, 0.278, -2.026);
  for (const std::string s : {"$VNYPR,+010.071,+000.278,-002.026*60\r\n", "$VNYPR,+010.071,+000.278,-002.026,T1162704*2F\r\n"}) {
    const Decoded r = decode(s);
    EXPECT_EQ(r.counters.frames, 1u) << s;
    EXPECT_LT(angle(only_sample(r), expected), 1e-12) << s;
  }
}

TEST(VectorNavDecoder, VendorPayloadsUnderAsyncHeadersDecodeToTheirValues) {
  EXPECT_LT(angle(only_sample(decode(kYpr8)), zyx(6.271, 0.031, -2.000)), 1e-12);
  EXPECT_LT(angle(only_sample(decode(kYmr27)), zyx(6.380, 0.023, -1.953)), 1e-12);
  // Scalar last on the wire: (x, y, z, w) -> posefair (w, x, y, z), normalised.
  const Quat q9 = Quat(0.998308, -0.017386, -0.000303, 0.055490).normalized();
  const Quat q15 = Quat(0.998255, -0.017057, -0.000767, 0.056534).normalized();
  const Quat got9 = only_sample(decode(kQtn9));
  const Quat got15 = only_sample(decode(kQmr15));
  EXPECT_NEAR((got9.coeffs() - q9.coeffs()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((got15.coeffs() - q15.coeffs()).norm(), 0.0, 1e-15);
  EXPECT_NEAR(got9.norm(), 1.0, 1e-15);
}

// VNQMR and VNYMR carry the compensated magnetic (Gauss), acceleration (m/s²) and angular rate
// (rad/s) beside the attitude: the sample has all of them, the field in µT.
TEST(VectorNavDecoder, AttitudeSentencesCarryTheirReadings) {
  const Decoded qmr = decode(kQmr15);
  ASSERT_EQ(qmr.samples.size(), 1u);
  EXPECT_EQ(qmr.samples[0].flags, kHasMag | kHasAccel | kHasGyro);
  EXPECT_NEAR((qmr.samples[0].mag - Vec3(106.70, -25.68, 306.96)).norm(), 0, 1e-9);
  EXPECT_EQ(qmr.samples[0].accel, Vec3(-0.019, 0.320, -9.802));
  EXPECT_EQ(qmr.samples[0].gyro, Vec3(-0.002801, -0.001186, -0.001582));
  const Decoded ymr = decode(kYmr27);
  ASSERT_EQ(ymr.samples.size(), 1u);
  EXPECT_EQ(ymr.samples[0].accel, Vec3(0.005, 0.344, -9.758));
  EXPECT_EQ(decode(kQtn9).samples[0].flags, 0u);  // the attitude alone
}

// Register 20's example response (UM001 §7.2.8, checksum as printed, VersaSync appendix 5.3.4.7)
// is a register reply: ignored. Its payload under the async header $VNMAR (checksum computed for
// this test) is a raw-only sample; so are $VNIMU (register 54, temperature and pressure not
// read) and the single-triple outputs.
TEST(VectorNavDecoder, RawOutputsGiveRawOnlySamples) {
  const std::string reg20 = "$VNRRG,20,+1.0684,-0.2578,+3.0649,-00.005,+00.341,-09.780,-0.000963,+0.000840,-0.000466*64\r\n";
  const std::string mar = "$VNMAR,+1.0684,-0.2578,+3.0649,-00.005,+00.341,-09.780,-0.000963,+0.000840,-0.000466*53\r\n";
  const Decoded r = decode(reg20 + mar);
  EXPECT_EQ(r.counters.frames, 2u);
  EXPECT_EQ(r.counters.ignored_frames, 1u);
  ASSERT_EQ(r.samples.size(), 1u);
  const DecodedSample& s = r.samples[0];
  EXPECT_EQ(s.flags, kNoOrientation | kHasMag | kHasAccel | kHasGyro);
  EXPECT_NEAR((s.mag - Vec3(106.84, -25.78, 306.49)).norm(), 0, 1e-9);
  EXPECT_EQ(s.accel, Vec3(-0.005, 0.341, -9.780));
  EXPECT_EQ(s.gyro, Vec3(-0.000963, 0.000840, -0.000466));

  const std::string imu_body = "VNIMU,-02.0841,+00.6045,+02.8911,+00.381,-00.154,-09.657,-00.005683,+00.001000,-00.002000,+021.6,+00099.761";
  const Decoded imu = decode("$" + imu_body + "*" + vectornav_checksum(imu_body, false) + "\r\n");
  ASSERT_EQ(imu.samples.size(), 1u);
  EXPECT_EQ(imu.samples[0].flags, kNoOrientation | kHasMag | kHasAccel | kHasGyro);
  EXPECT_EQ(imu.samples[0].gyro, Vec3(-0.005683, 0.001, -0.002));
  EXPECT_NEAR(imu.samples[0].mag.x(), -208.41, 1e-9);

  const std::string acc_body = "VNACC,+00.013,+00.354,-09.801";  // register 18's example payload
  const Decoded acc = decode("$" + acc_body + "*" + vectornav_checksum(acc_body, true) + "\r\n");
  ASSERT_EQ(acc.samples.size(), 1u);
  EXPECT_EQ(acc.samples[0].flags, kNoOrientation | kHasAccel);
  EXPECT_EQ(acc.samples[0].accel, Vec3(0.013, 0.354, -9.801));

  const std::string short_body = "VNMAR,+1.0684,-0.2578,+3.0649";  // too few numbers
  EXPECT_EQ(decode("$" + short_body + "*" + vectornav_checksum(short_body, false) + "\r\n").counters.malformed, 1u);
}

// The manual's examples were read one after the other from one sensor: the Euler and the
// quaternion readings must describe (nearly) the same attitude. Read as body→NED Hamilton
// quaternions without a conjugate they agree to ~0.1°; conjugated they would be ~2·yaw apart.
TEST(VectorNavConventions, ManualExamplePairsAgreeOnlyWithoutConjugate) {
  const Quat ypr8 = only_sample(decode(kYpr8));
  const Quat qtn9 = only_sample(decode(kQtn9));
  const Quat ymr27 = only_sample(decode(kYmr27));
  const Quat qmr15 = only_sample(decode(kQmr15));
  EXPECT_LT(angle(ypr8, qtn9), 0.2 * kDeg);
  EXPECT_LT(angle(ymr27, qmr15), 0.2 * kDeg);
  EXPECT_GT(angle(ypr8, qtn9.conjugate()), 10.0 * kDeg);
  EXPECT_GT(angle(ymr27, qmr15.conjugate()), 10.0 * kDeg);
}

Vec3 turn(const Decoded& r, const Vec3& v) { return only_sample(r) * v; }

TEST(VectorNavConventions, YawPitchRollAreIntrinsicZyxFromBodyToNed) {
  const auto ymr = [](double y, double p, double r) { return decode(encode_vectornav_vnymr(y, p, r, false)); };
  // Yaw 90° alone: body x (forward) onto NED y (east).
  EXPECT_LT((turn(ymr(90, 0, 0), Vec3::UnitX()) - Vec3::UnitY()).norm(), 1e-12);
  // Pitch 90° alone (nose up): body x onto -z (up in NED).
  EXPECT_LT((turn(ymr(0, 90, 0), Vec3::UnitX()) + Vec3::UnitZ()).norm(), 1e-12);
  // Roll 90° alone (right wing down): body y onto +z (down).
  EXPECT_LT((turn(ymr(0, 0, 90), Vec3::UnitY()) - Vec3::UnitZ()).norm(), 1e-12);
  // Yaw 90° then pitch 30° about the new y axis: x -> Rz(90)·Ry(30)·x = (0, cos30, -sin30).
  // (The extrinsic order Ry(30)·Rz(90) would give (0, 1, 0).)
  const Vec3 v = turn(ymr(90, 30, 0), Vec3::UnitX());
  EXPECT_LT((v - Vec3(0, std::cos(30 * kDeg), -std::sin(30 * kDeg))).norm(), 1e-12);
}

TEST(VectorNavConventions, QuaternionScalarIsLastOnTheWire) {
  // 90° about z, written x y z w: turns x onto y.
  const std::string body = "VNQTN,+0.000000,+0.000000,+0.707107,+0.707107";
  const Decoded r = decode("$" + body + "*" + vectornav_checksum(body, false) + "\r\n");
  EXPECT_LT((turn(r, Vec3::UnitX()) - Vec3::UnitY()).norm(), 1e-6);
}

TEST(VectorNavChecksum, FieldsAreXorAndCrc16Xmodem) {
  EXPECT_EQ(vectornav_checksum("VNRRG,11", false), "73");          // UM004 §3.1
  EXPECT_EQ(vectornav_checksum("VNYPR,+010.071,+000.278,-002.026", false), "60");  // UM004 §5.11.1
  EXPECT_EQ(vectornav_checksum("123456789", true), "31C3");       // CRC-16/XMODEM check value
}

TEST(VectorNavRoundTrip, RandomQuaternionsBothChecksums) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  for (const bool crc : {false, true}) {
    std::string stream;
    std::vector<Quat> truth;
    for (int k = 0; k < 2000; ++k) {
      Quat q(n01(rng), n01(rng), n01(rng), n01(rng));
      q.normalize();
      truth.push_back(q);
      stream += encode_vectornav_vnqmr(q, crc);
    }
    const Decoded r = decode(stream);
    ASSERT_EQ(r.samples.size(), truth.size());
    EXPECT_EQ(r.counters.frames, truth.size());
    EXPECT_EQ(r.counters.malformed + r.counters.bad_checksum + r.counters.skipped_bytes, 0u);
    for (std::size_t k = 0; k < truth.size(); ++k) {
      EXPECT_LT(angle(r.samples[k].orientation, truth[k]), 5e-6) << k;  // 6 decimals per component
      EXPECT_NEAR(r.samples[k].orientation.norm(), 1.0, 1e-15);
    }
  }
}

TEST(VectorNavRoundTrip, RandomYawPitchRollBothChecksums) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> yaw(-180, 180), pitch(-90, 90), roll(-180, 180);
  for (const bool crc : {false, true}) {
    std::string stream;
    std::vector<Quat> truth;
    for (int k = 0; k < 2000; ++k) {
      const double y = yaw(rng), p = pitch(rng), r = roll(rng);
      truth.push_back(zyx(y, p, r));
      stream += encode_vectornav_vnymr(y, p, r, crc);
    }
    const Decoded r = decode(stream);
    ASSERT_EQ(r.samples.size(), truth.size());
    for (std::size_t k = 0; k < truth.size(); ++k)
      EXPECT_LT(angle(r.samples[k].orientation, truth[k]), 3 * 0.0005 * kDeg) << k;  // 3 decimals of degrees
  }
}

// A stream with every kind of event: good sentences of each kind and checksum, vendor lines,
// garbage between and within sentences, a bad checksum, a disabled checksum, an over-long line.
std::string mixed_stream() {
  std::mt19937_64 rng(3);
  std::string s = "\x01\xff garbage before";
  s += kQmr15 + kYmr27 + kReg9 + "noise$VNYMR,+001";  // a truncated sentence, then a new one
  s += encode_vectornav_vnqmr(Quat(0.5, 0.5, -0.5, 0.5), true);
  s += encode_vectornav_vnymr(-120.5, 45.25, 170.0, true);
  std::string bad = encode_vectornav_vnymr(10, 20, 30, false);
  bad[10] = bad[10] == '1' ? '2' : '1';
  s += bad;
  s += "$VNYPR,+010.071,+000.278,-002.026*XX\r\n";
  s += "$" + std::string(400, 'A') + "\r\n";  // over-long
  s += std::string("\x00\x00$VN\x80", 6);
  s += kYpr8 + kQtn9 + "$VNQTN,+0.5*00\r\n";
  for (int k = 0; k < 5; ++k) s += encode_vectornav_vnymr(k * 7.0, -k * 3.0, k * 11.0, (k % 2) == 0);
  return s;
}

TEST(VectorNavStream, AnySplitGivesIdenticalSamplesAndCounters) {
  const std::string stream = mixed_stream();
  const Decoded whole = decode(stream);
  EXPECT_EQ(whole.samples.size(), 11u);
  EXPECT_EQ(whole.counters.bad_checksum, 3u);  // flipped digit, "XX", "$VNQTN,+0.5*00"
  EXPECT_EQ(whole.counters.bytes, stream.size());
  const auto make = [] { return make_vectornav_decoder({}); };
  expect_every_split_same(make, bytes_of(stream), whole);
  expect_byte_by_byte_same(make, bytes_of(stream), whole);
  std::mt19937_64 rng(5);
  expect_random_chunkings_same(make, bytes_of(stream), whole, rng, 200, {40});
}

TEST(VectorNavResync, GarbageBeforeAndBetweenSentences) {
  const std::string garbage("\x00\x13\xfe\r\n*,VN12", 11);
  const Decoded r = decode(garbage + kYpr8 + garbage + kYpr8);
  EXPECT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.counters.resyncs, 2u);
  EXPECT_EQ(r.counters.skipped_bytes, 2 * garbage.size());
  EXPECT_EQ(r.counters.bad_checksum, 0u);
}

TEST(VectorNavResync, TruncatedSentenceIsDroppedAtTheNextDollar) {
  const std::string half = kQmr15.substr(0, 60);
  const Decoded r = decode(half + kQmr15);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.counters.frames, 1u);
  EXPECT_EQ(r.counters.resyncs, 1u);
  EXPECT_EQ(r.counters.skipped_bytes, half.size());
}

TEST(VectorNavResync, NonTextByteEndsASentence) {
  std::string broken = kYmr27;
  broken[30] = '\x07';
  const Decoded r = decode(broken + kYmr27);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.counters.bad_checksum, 0u);
  EXPECT_EQ(r.counters.skipped_bytes, broken.size());  // from '$' through '\n'
}

TEST(VectorNavResync, BadChecksumIsCountedAndTheNextSentenceDecodes) {
  for (const bool crc : {false, true}) {
    const std::string good = encode_vectornav_vnqmr(Quat(0.6, 0.0, 0.8, 0.0), crc);
    std::string flipped_digit = good;
    flipped_digit[12] = flipped_digit[12] == '0' ? '9' : '0';
    std::string flipped_checksum = good;
    const std::size_t star = good.find('*');
    flipped_checksum[star + 1] = flipped_checksum[star + 1] == 'A' ? 'B' : 'A';
    std::string no_star = good;
    no_star[star] = '#';
    const Decoded r = decode(flipped_digit + good + flipped_checksum + good + no_star + good);
    EXPECT_EQ(r.counters.bad_checksum, 3u) << crc;
    EXPECT_EQ(r.counters.frames, 3u) << crc;
    EXPECT_EQ(r.samples.size(), 3u) << crc;
    EXPECT_EQ(r.counters.skipped_bytes, 0u) << crc;
  }
}

TEST(VectorNavResync, EverySingleCharacterCorruptionIsRejected) {
  // XOR and the CRC both catch any single changed byte: every such variant of a sentence is
  // refused (bad checksum, or skipped when the change broke the framing), never decoded.
  for (const bool crc : {false, true}) {
    const std::string good = encode_vectornav_vnymr(12.5, -33.25, 101.0, crc);
    for (std::size_t at = 1; at + 2 < good.size(); ++at) {
      for (const char c : std::string("0123456789+-.,*ABCDEFVNX")) {
        if (c == good[at]) continue;
        std::string s = good;
        s[at] = c;
        const Decoded r = decode(s);
        EXPECT_EQ(r.samples.size(), 0u) << crc << " " << s;
      }
    }
  }
}

TEST(VectorNavResync, OverlongSentenceIsDiscardedNotBuffered) {
  const std::string junk = "$" + std::string(10000, 'A');  // no '\n' at all
  const Decoded r = decode(junk + kYpr8);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(r.counters.resyncs, 1u);
  EXPECT_EQ(r.counters.skipped_bytes, junk.size());
  EXPECT_EQ(r.counters.bad_checksum, 0u);

  // The bound is exact: 256 bytes from '$' through '\n' is kept, 257 is not.
  const auto line = [](std::size_t total) {
    const std::string body = "VNZZZ," + std::string(total - 12, 'B');  // "$" body "*CS\r\n"
    return "$" + body + "*" + vectornav_checksum(body, false) + "\r\n";
  };
  ASSERT_EQ(line(kVectorNavMaxSentence).size(), kVectorNavMaxSentence);
  const Decoded at_bound = decode(line(kVectorNavMaxSentence));
  EXPECT_EQ(at_bound.counters.frames, 1u);
  EXPECT_EQ(at_bound.counters.ignored_frames, 1u);
  const Decoded over = decode(line(kVectorNavMaxSentence + 1) + kYpr8);
  EXPECT_EQ(over.counters.frames, 1u);  // only the YPR
  EXPECT_EQ(over.samples.size(), 1u);
  EXPECT_EQ(over.counters.skipped_bytes, kVectorNavMaxSentence + 1);
}

TEST(VectorNavChecksumOff, XXIsRejectedByDefaultAndAcceptedOnRequest) {
  const std::string unchecked = "$VNYPR,+010.071,+000.278,-002.026*XX\r\n";
  const std::string unchecked4 = "$VNYPR,+010.071,+000.278,-002.026*XXXX\r\n";
  const Decoded def = decode(unchecked + unchecked4);
  EXPECT_EQ(def.counters.bad_checksum, 2u);
  EXPECT_EQ(def.counters.frames, 0u);
  EXPECT_TRUE(def.samples.empty());

  OptionMap accept;
  accept["vectornav_unchecked"] = std::string("accept");
  const Decoded acc = decode_with(unchecked + unchecked4, accept);
  EXPECT_EQ(acc.counters.frames, 2u);
  ASSERT_EQ(acc.samples.size(), 2u);
  EXPECT_LT(angle(acc.samples[0].orientation, zyx(10.071, 0.278, -2.026)), 1e-12);

  // Unchecked sentences must also look exactly like the device's output.
  const Decoded odd = decode_with("$VNYPR,10.071,+000.278,-002.026*XX\r\n$VNYPR,+010.071,+000.278,-002.026,X1*XX\r\n", accept);
  EXPECT_EQ(odd.counters.malformed, 2u);
  EXPECT_TRUE(odd.samples.empty());
  // ... while a checked sentence need not (its checksum already vouches for it).
  const std::string body = "VNYPR,10.071,0.278,-2.026";
  EXPECT_EQ(decode("$" + body + "*" + vectornav_checksum(body, false) + "\r\n").samples.size(), 1u);

  OptionMap wrong;
  wrong["vectornav_unchecked"] = std::string("yes");
  EXPECT_THROW(make_vectornav_decoder(wrong), std::invalid_argument);
}

TEST(VectorNavMalformed, ValidChecksumButImpossibleContents) {
  const auto with_checksum = [](const std::string& body) {
    return "$" + body + "*" + vectornav_checksum(body, false) + "\r\n";
  };
  const std::vector<std::string> bodies = {
      "VNYPR,+010.071,+000.278",                          // too few numbers
      "VNYPR,+010.071,+000.278,abc",                       // not a number
      "VNYPR,+010.071,+000.278,nan",                       // not finite
      "VNYPR,+010.071,+091.000,+000.000",                  // pitch beyond 90°
      "VNYPR,+180.500,+000.000,+000.000",                  // yaw beyond 180°
      "VNYPR,+010.071,+000.278,-002.026,Q5",               // trailing field not T/S
      "VNYPR,+010.071,+000.278,-002.026,T1,S2,T3",         // three trailing fields
      "VNYPR,+010.071,+000.278,-002.026,",                 // empty trailing field
      "VNQTN,+0.500000,+0.000000,+0.000000,+0.500000",     // norm 0.71
      "VNQTN,+0.000000,+0.000000,+0.000000,+0.000000",     // zero
      "VNQTN,+1.000000,+0.000000,+0.000000,+1e999",        // out of range
      "VNQMR,+0.000000,+0.000000,+0.000000,+1.000000",     // QMR without mag/accel/rate
      "VNYMR",                                             // header only
  };
  std::string stream;
  for (const std::string& b : bodies) stream += with_checksum(b);
  const Decoded r = decode(stream);
  EXPECT_EQ(r.counters.frames, bodies.size());
  EXPECT_EQ(r.counters.malformed, bodies.size());
  EXPECT_TRUE(r.samples.empty());
  // Trailing T and S fields (SerialCount, SerialStatus) are fine.
  EXPECT_EQ(decode(with_checksum("VNYPR,+010.071,+000.278,-002.026,T1162704,S0004")).samples.size(), 1u);
}

TEST(VectorNavDecoder, ResetForgetsAPartialSentence) {
  auto d = make_vectornav_decoder({});
  Collector r;
  d->feed(bytes_of(kYpr8.substr(0, 20)), r);
  d->reset();
  d->feed(bytes_of(kYpr8.substr(20)), r);
  EXPECT_TRUE(r.samples.empty());
  d->feed(bytes_of(kYpr8), r);
  EXPECT_EQ(r.samples.size(), 1u);
  EXPECT_EQ(d->counters().skipped_bytes, kYpr8.size());
}

// The checksum's own false-accept rate: valid sentences whose checksum field is replaced by
// random hex digits are accepted with probability 1/256 (XOR) or 1/65536 (CRC-16), no more.
TEST(VectorNavRandom, RandomChecksumFieldsAreAcceptedAtTheChecksumsRate) {
  std::mt19937_64 rng(13);
  const std::string hex = "0123456789ABCDEF";
  constexpr int kN = 200000;
  for (const bool crc : {false, true}) {
    std::string stream;
    for (int k = 0; k < kN; ++k) {
      std::string s = encode_vectornav_vnymr(k % 360 - 179.5, 10.0, -20.0, crc);
      const std::size_t star = s.find('*');
      for (std::size_t i = star + 1; i < s.size() - 2; ++i) s[i] = hex[rng() % 16];
      stream += s;
    }
    const Decoded r = decode(stream);
    SCOPED_TRACE(crc ? "CRC-16" : "XOR");
    expect_binomial_within(r.counters.frames, kN, crc ? 1.0 / 65536 : 1.0 / 256, 3);
    EXPECT_EQ(r.counters.frames + r.counters.bad_checksum, static_cast<std::uint64_t>(kN));
  }
}

// 10 MB of seeded random bytes: no crash, and no frame beyond what the checksum lets through.
// A random '$' opens a sentence that survives only while bytes stay printable (95/256 each), so
// about 0.6% of the ~39000 '$' reach a '\n'; such a line then needs "*" two or four places from
// its end, hex digits there, and a matching checksum (1/256 at best): expected false frames
// ≈ 1e-4. The bound allows 2.
TEST(VectorNavRandom, TenMegabytesOfRandomBytes) {
  std::mt19937_64 rng(1);
  const std::vector<std::uint8_t> data = random_bytes(10'000'000, rng);
  const Decoded r = decode_in_random_reads(make_vectornav_decoder({}), data, rng);
  EXPECT_EQ(r.counters.bytes, data.size());
  EXPECT_LE(r.counters.frames, 2u);
  expect_unit_quaternions(r.samples);
}

// The fuzz seed corpus (tests/fuzz/corpus/vectornav/) is written by a separate generator
// (Python, not these encoders): it must decode as intended, CRC-16 sentences included.
TEST(VectorNavCorpus, SeedFilesDecodeAsIntended) {
  const std::string dir = std::string(POSEFAIR_SOURCE_DIR) + "/tests/fuzz/corpus/vectornav/";
  const Decoded vendor = decode(::posefair::testing::slurp(dir + "vendor_examples.txt"));
  EXPECT_EQ(vendor.counters.frames, 8u);
  EXPECT_EQ(vendor.samples.size(), 2u);  // the two $VNYPR lines
  for (const char* name : {"vnqmr_xor.txt", "vnymr_crc16.txt"}) {
    const Decoded r = decode(::posefair::testing::slurp(dir + name));
    EXPECT_EQ(r.samples.size(), 12u) << name;
    EXPECT_EQ(r.counters.bad_checksum + r.counters.malformed + r.counters.skipped_bytes, 0u) << name;
  }
  // Same smooth motion, written once as quaternions and once as angles.
  const Decoded q = decode(::posefair::testing::slurp(dir + "vnqmr_xor.txt"));
  const Decoded e = decode(::posefair::testing::slurp(dir + "vnymr_crc16.txt"));
  ASSERT_EQ(q.samples.size(), e.samples.size());
  for (std::size_t k = 0; k < q.samples.size(); ++k)
    EXPECT_LT(angle(q.samples[k].orientation, e.samples[k].orientation), 1e-4) << k;
  const Decoded mixed = decode(::posefair::testing::slurp(dir + "mixed_garbage.bin"));
  EXPECT_EQ(mixed.samples.size(), 4u);
  EXPECT_EQ(mixed.counters.bad_checksum, 2u);
}

}  // namespace
}  // namespace posefair::drivers::vectornav_decoder_test
