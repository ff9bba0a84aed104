// The encodings for existing clients (docs/outputs.md): the frame mapping (client_frames.hpp)
// checked with known rotations as each client shows them, opentrack and FreeD against golden
// bytes and against decoders written here from the published layouts (not from the encoders),
// and the option errors of every encoding with per-stream options.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/output_rate_limit.hpp"
#include "known_rotations.hpp"

namespace posefair::daemon {
namespace {

using posefair::testing::kDeg;
using posefair::testing::lean_right;
using posefair::testing::pitch_up;
using posefair::testing::pose;
using posefair::testing::turn_left;

std::shared_ptr<const OutputEncoder> make(std::string_view encoding, const posefair::OptionMap& options = {},
                                          std::vector<OutputStream> streams = {{1, "head"}}) {
  const OutputEncoderEntry* e = find_output_encoder(encoding);
  if (e == nullptr) throw std::logic_error("no encoding " + std::string(encoding));
  return e->make(options, streams);
}

std::vector<std::uint8_t> encode(const OutputEncoder& encoder, const PoseMessage& m) {
  std::vector<std::uint8_t> buffer(kMaxDatagramSize);
  buffer.resize(encoder.encode(m, buffer));
  return buffer;
}

// --- Frames -----------------------------------------------------------------------------------

TEST(ClientFrames, HeadAnglesOfATurnLeftAPitchUpAndALeanRight) {
  const HeadAngles left = head_angles(turn_left(90));
  EXPECT_NEAR(left.yaw, 90.0, 1e-9);
  EXPECT_NEAR(left.pitch, 0.0, 1e-9);
  EXPECT_NEAR(left.roll, 0.0, 1e-9);
  const HeadAngles up = head_angles(pitch_up(30));
  EXPECT_NEAR(up.yaw, 0.0, 1e-9);
  EXPECT_NEAR(up.pitch, 30.0, 1e-9);
  EXPECT_NEAR(up.roll, 0.0, 1e-9);
  EXPECT_NEAR(head_angles(lean_right(20)).roll, 20.0, 1e-9);
  // Turned left, then looking up: the head order (yaw, then pitch in the turned frame).
  const HeadAngles both = head_angles(turn_left(40) * pitch_up(25));
  EXPECT_NEAR(both.yaw, 40.0, 1e-9);
  EXPECT_NEAR(both.pitch, 25.0, 1e-9);
}

TEST(ClientFrames, AtStraightUpTheTurnIsAllYaw) {
  // Gimbal lock: only yaw ± roll is defined; the whole turn goes into yaw (roll 0).
  const HeadAngles up = head_angles(turn_left(30) * pitch_up(90));
  EXPECT_NEAR(up.pitch, 90.0, 1e-6);
  EXPECT_NEAR(up.yaw, 30.0, 1e-6);
  EXPECT_NEAR(up.roll, 0.0, 1e-6);
  const std::array<double, 3> e = unity_euler_zxy(unity_rotation(turn_left(30) * pitch_up(90)));
  EXPECT_NEAR(e[0], -90.0, 1e-6);
  EXPECT_NEAR(e[1], -30.0, 1e-6);
  EXPECT_NEAR(e[2], 0.0, 1e-6);
}

TEST(ClientFrames, HeadAnglesComposeBackToTheRotation) {
  for (const Quat& q : {Quat(Eigen::AngleAxisd(2.5, Vec3(-0.3, 0.5, 0.8).normalized())),
                        Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, -0.5).normalized())), turn_left(179) * lean_right(-170)}) {
    const HeadAngles a = head_angles(q);
    EXPECT_LE(std::abs(a.pitch), 90.0);
    const Quat back = turn_left(a.yaw) * pitch_up(a.pitch) * lean_right(a.roll);
    EXPECT_NEAR(std::abs(back.dot(q)), 1.0, 1e-12);
  }
}

TEST(ClientFrames, UnityShowsATurnLeftAsNegativeYAndAPitchUpAsNegativeX) {
  // Unity: x right, y up, z forward, left-handed; Quaternion.Euler(0, 90, 0) turns to the right.
  const std::array<double, 3> left = unity_euler_zxy(unity_rotation(turn_left(90)));
  EXPECT_NEAR(left[0], 0.0, 1e-9);
  EXPECT_NEAR(left[1], -90.0, 1e-9);
  EXPECT_NEAR(left[2], 0.0, 1e-9);
  const std::array<double, 3> up = unity_euler_zxy(unity_rotation(pitch_up(30)));
  EXPECT_NEAR(up[0], -30.0, 1e-9);
  EXPECT_NEAR(up[1], 0.0, 1e-9);
  EXPECT_NEAR(up[2], 0.0, 1e-9);
  // Leaning right is a clockwise roll seen from behind: about Unity's forward axis, negative.
  EXPECT_NEAR(unity_euler_zxy(unity_rotation(lean_right(15)))[2], -15.0, 1e-9);
}

TEST(ClientFrames, UnityRotationMovesUnityVectorsAsPosefairMovesItsOwn) {
  // For any rotation and vector: mapping the rotated vector equals rotating the mapped vector.
  const Quat q = Quat(Eigen::AngleAxisd(1.1, Vec3(0.3, -0.5, 0.8).normalized()));
  const Vec3 v(0.2, -1.3, 0.7);
  const Vec3 a = unity_position(q * v);
  const Vec3 b = unity_rotation(q) * unity_position(v);
  EXPECT_LT((a - b).norm(), 1e-12);
  // And Unity's Euler angles compose back to it: Ry(y) Rx(x) Rz(z).
  const std::array<double, 3> e = unity_euler_zxy(unity_rotation(q));
  const Quat back = Quat(Eigen::AngleAxisd(e[1] * kDeg, Vec3::UnitY())) * Quat(Eigen::AngleAxisd(e[0] * kDeg, Vec3::UnitX())) *
                    Quat(Eigen::AngleAxisd(e[2] * kDeg, Vec3::UnitZ()));
  EXPECT_NEAR(std::abs(back.dot(unity_rotation(q))), 1.0, 1e-12);
}

TEST(ClientFrames, UnityPositionIsRightUpForward) {
  EXPECT_EQ(unity_position(Vec3(1, 0, 0)), Vec3(0, 0, 1));   // forward
  EXPECT_EQ(unity_position(Vec3(0, 1, 0)), Vec3(-1, 0, 0));  // left
  EXPECT_EQ(unity_position(Vec3(0, 0, 1)), Vec3(0, 1, 0));   // up
}

TEST(ClientFrames, MountingAndWorldCorrectACrookedTracker) {
  // A tracker mounted turned 90° to the left on a head that faces forward reports a left turn;
  // mounting = its inverse makes the head face forward again. world turns what clients see.
  StreamFrame f;
  f.mounting = rotation_from_zyx_degrees(-90, 0, 0);
  EXPECT_TRUE(f.orientation(turn_left(90)).isApprox(Quat::Identity(), 1e-12));
  f.world = rotation_from_zyx_degrees(0, 0, 0) * turn_left(10);
  EXPECT_NEAR(head_angles(f.orientation(turn_left(90) * pitch_up(20))).yaw, 10.0, 1e-9);
  EXPECT_NEAR(head_angles(f.orientation(turn_left(90) * pitch_up(20))).pitch, 0.0, 1e-9);  // pitch was about the sensor's axis
  EXPECT_LT((f.position(Vec3(1, 0, 0)) - Vec3(std::cos(10 * kDeg), std::sin(10 * kDeg), 0)).norm(), 1e-12);
  EXPECT_TRUE(StreamFrame{}.identity());
  EXPECT_FALSE(f.identity());
}

TEST(ClientFrames, RotationFromZyxDegreesIsRzRyRx) {
  const Quat q = rotation_from_zyx_degrees(30, -20, 10);
  const Quat expected = Quat(Eigen::AngleAxisd(30 * kDeg, Vec3::UnitZ())) * Quat(Eigen::AngleAxisd(-20 * kDeg, Vec3::UnitY())) *
                        Quat(Eigen::AngleAxisd(10 * kDeg, Vec3::UnitX()));
  EXPECT_NEAR(std::abs(q.dot(expected)), 1.0, 1e-12);
}

// --- opentrack --------------------------------------------------------------------------------

// opentrack's "UDP over network" layout as its documentation gives it: 6 little-endian doubles.
struct OpentrackPacket {
  double x, y, z, yaw, pitch, roll;
};
OpentrackPacket decode_opentrack(const std::vector<std::uint8_t>& d) {
  EXPECT_EQ(d.size(), 48u);
  double v[6] = {};
  for (int i = 0; i < 6; ++i) {
    std::uint64_t bits = 0;
    for (int b = 7; b >= 0; --b) bits = (bits << 8) | d[static_cast<std::size_t>(8 * i + b)];
    std::memcpy(&v[i], &bits, 8);
  }
  return {v[0], v[1], v[2], v[3], v[4], v[5]};
}

TEST(OpentrackEncoding, GoldenBytes) {
  // Position (1 m forward, 0.5 m left, 0.25 m up), turned 90° left: x = -50 cm (right is +),
  // y = 25 cm, z = -100 cm (back is +), yaw 90.
  const auto d = encode(*make("opentrack"), pose(turn_left(90), Vec3(1.0, 0.5, 0.25)));
  const std::vector<std::uint8_t> golden = {
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x49, 0xC0,  // -50
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x39, 0x40,  // 25
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x59, 0xC0,  // -100
      0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x56, 0x40,  // 90
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // 0
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // 0
  };
  ASSERT_EQ(d.size(), golden.size());
  for (std::size_t i = 0; i < 24; ++i) EXPECT_EQ(d[i], golden[i]) << "byte " << i;
  const OpentrackPacket p = decode_opentrack(d);
  EXPECT_NEAR(p.yaw, 90.0, 1e-9);
  EXPECT_NEAR(p.pitch, 0.0, 1e-9);
  EXPECT_NEAR(p.roll, 0.0, 1e-9);
}

TEST(OpentrackEncoding, ATurnLeftAPitchUpAndALeanAsOpentrackShowsThem) {
  const auto opentrack = make("opentrack");
  EXPECT_NEAR(decode_opentrack(encode(*opentrack, pose(turn_left(90)))).yaw, 90.0, 1e-9);
  EXPECT_NEAR(decode_opentrack(encode(*opentrack, pose(pitch_up(30)))).pitch, 30.0, 1e-9);
  EXPECT_NEAR(decode_opentrack(encode(*opentrack, pose(lean_right(12)))).roll, 12.0, 1e-9);
  const OpentrackPacket none = decode_opentrack(encode(*opentrack, pose(Quat::Identity())));
  EXPECT_EQ(none.x, 0.0);
  EXPECT_EQ(none.y, 0.0);
  EXPECT_EQ(none.z, 0.0);
}

TEST(OpentrackEncoding, NeverSendsNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const OpentrackPacket p = decode_opentrack(encode(*make("opentrack"), pose(Quat::Identity(), Vec3(nan, 1.0, nan))));
  for (double v : {p.x, p.y, p.z, p.yaw, p.pitch, p.roll}) EXPECT_TRUE(std::isfinite(v));
  EXPECT_EQ(p.x, -100.0);  // y = 1 m left: -100 cm (right is +)
  EXPECT_EQ(p.z, 0.0);
}

// --- FreeD ------------------------------------------------------------------------------------

// The D1 message from the free-d manual's layout, decoded here independently of the encoder.
struct FreedPacket {
  int camera;
  double pan, tilt, roll;  // degrees
  double x, y, z;          // mm
  std::uint32_t zoom, focus;
};
std::int32_t be24_signed(const std::vector<std::uint8_t>& d, std::size_t at) {
  std::int32_t v = (d[at] << 16) | (d[at + 1] << 8) | d[at + 2];
  if (v & 0x800000) v -= 0x1000000;
  return v;
}
FreedPacket decode_freed(const std::vector<std::uint8_t>& d) {
  EXPECT_EQ(d.size(), 29u);
  EXPECT_EQ(d[0], 0xD1);
  unsigned sum = 0;  // the checksum makes the sum of all 29 bytes 0x40 (mod 256)
  for (std::uint8_t b : d) sum += b;
  EXPECT_EQ(sum % 256, 0x40u) << "checksum";
  auto u24 = [&](std::size_t at) { return static_cast<std::uint32_t>((d[at] << 16) | (d[at + 1] << 8) | d[at + 2]); };
  return {d[1],
          be24_signed(d, 2) / 32768.0,
          be24_signed(d, 5) / 32768.0,
          be24_signed(d, 8) / 32768.0,
          be24_signed(d, 11) / 64.0,
          be24_signed(d, 14) / 64.0,
          be24_signed(d, 17) / 64.0,
          u24(20),
          u24(23)};
}

TEST(FreedEncoding, GoldenBytes) {
  // Stream 7, pitched up 45°, at (2 m forward, 1 m left, 1.5 m up), zoom 0x123456, focus 0xABCDEF.
  const auto freed = make("freed", {{"zoom", std::int64_t{0x123456}}, {"focus", std::int64_t{0xABCDEF}}}, {{7, "camera"}});
  const auto d = encode(*freed, pose(pitch_up(45), Vec3(2.0, 1.0, 1.5), 7));
  const std::vector<std::uint8_t> golden = {
      0xD1, 0x07,
      0x00, 0x00, 0x00,  // pan 0
      0x16, 0x80, 0x00,  // tilt 45 * 32768 = 0x168000
      0x00, 0x00, 0x00,  // roll 0
      0xFF, 0x06, 0x00,  // X = -1000 mm * 64 = -64000 = 0xFF0600 (right is +)
      0x01, 0xF4, 0x00,  // Y = 2000 mm * 64 = 128000 = 0x01F400
      0x01, 0x77, 0x00,  // Z = 1500 mm * 64 = 96000 = 0x017700
      0x12, 0x34, 0x56, 0xAB, 0xCD, 0xEF, 0x00, 0x00,
      0x00,  // checksum, filled below from the manual's rule
  };
  std::vector<std::uint8_t> expected = golden;
  unsigned sum = 0;
  for (std::size_t i = 0; i < 28; ++i) sum += expected[i];
  expected[28] = static_cast<std::uint8_t>((0x40 - sum) & 0xFF);
  EXPECT_EQ(expected[28], 0x5D);  // 0x40 - (sum = 1763 = 0x6E3) mod 256
  EXPECT_EQ(d, expected);
}

TEST(FreedEncoding, ATurnLeftIsANegativePanAndAPitchUpAPositiveTilt) {
  const auto freed = make("freed");
  const FreedPacket left = decode_freed(encode(*freed, pose(turn_left(90))));
  EXPECT_NEAR(left.pan, -90.0, 1.0 / 32768);  // pan is clockwise seen from above
  EXPECT_NEAR(left.tilt, 0.0, 1.0 / 32768);
  const FreedPacket up = decode_freed(encode(*freed, pose(pitch_up(30))));
  EXPECT_NEAR(up.tilt, 30.0, 1.0 / 32768);
  EXPECT_NEAR(up.pan, 0.0, 1.0 / 32768);
  EXPECT_NEAR(decode_freed(encode(*freed, pose(lean_right(10)))).roll, 10.0, 1.0 / 32768);
  EXPECT_EQ(left.camera, 1);  // the stream's id
  EXPECT_EQ(left.zoom, 0u);
}

TEST(FreedEncoding, PositionsBeyondTheRangeAreHeldAtIt) {
  const FreedPacket p = decode_freed(encode(*make("freed"), pose(Quat::Identity(), Vec3(500.0, -0.001, 0.0))));
  EXPECT_NEAR(p.y, 0x7FFFFF / 64.0, 1e-9);  // 500 m forward: the largest value, not a wrapped one
  EXPECT_NEAR(p.x, 1.0, 1e-9);              // 1 mm to the right
}

TEST(FreedEncoding, CameraIdsAndTheirErrors) {
  const auto one = make("freed", {{"camera_id", std::int64_t{42}}}, {{300, "crane"}});
  EXPECT_EQ(decode_freed(encode(*one, pose(Quat::Identity(), std::nullopt, 300))).camera, 42);
  auto key_of = [](const posefair::OptionMap& o, std::vector<OutputStream> s) -> std::string {
    try {
      (void)make("freed", o, std::move(s));
    } catch (const posefair::OptionError& e) {
      return e.key();
    }
    return "accepted";
  };
  EXPECT_EQ(key_of({}, {{300, "crane"}}), "camera_id");  // does not fit a D1 camera id
  EXPECT_EQ(key_of({{"camera_id", std::int64_t{1}}}, {{1, "a"}, {2, "b"}}), "camera_id");
  EXPECT_EQ(key_of({{"camera_id", std::int64_t{256}}}, {{1, "a"}}), "camera_id");
  EXPECT_EQ(key_of({{"zoom", std::int64_t{1 << 24}}}, {{1, "a"}}), "zoom");
}

// --- OSC encodings: options (the bytes are checked by oscdump, osc_oscdump_test.cpp) -----------

std::string refused_key(std::string_view encoding, const posefair::OptionMap& o, std::vector<OutputStream> s) {
  try {
    (void)make(encoding, o, std::move(s));
  } catch (const posefair::OptionError& e) {
    return e.key();
  }
  return "accepted";
}

TEST(VmcEncoding, BonesAreUnityHumanBodyBonesOnePerStream) {
  const std::vector<OutputStream> two = {{1, "head"}, {2, "hips"}};
  using Names = std::vector<std::string>;
  EXPECT_EQ(refused_key("vmc", {{"bones", Names{"Head", "Hips"}}}, two), "accepted");
  EXPECT_EQ(refused_key("vmc", {{"bones", Names{"Head", "Root"}}}, two), "accepted");
  EXPECT_EQ(refused_key("vmc", {{"bones", Names{"Head", "Pelvis"}}}, two), "bones[2]");
  EXPECT_EQ(refused_key("vmc", {{"bones", Names{"head", "Hips"}}}, two), "bones[1]");  // Unity's names are case-sensitive
  EXPECT_EQ(refused_key("vmc", {{"bones", Names{"Head", "Head"}}}, two), "bones[2]");
  EXPECT_EQ(refused_key("vmc", {{"bones", Names{"Head"}}}, two), "bones");
  EXPECT_EQ(refused_key("vmc", {}, two), "bones");
  EXPECT_EQ(refused_key("vmc", {}, {{1, "head"}}), "accepted");  // one stream: the root
}

TEST(VrchatEncoding, TrackersAreOneToEightOrHeadOnePerStream) {
  const std::vector<OutputStream> two = {{1, "hip"}, {2, "head"}};
  using Names = std::vector<std::string>;
  EXPECT_EQ(refused_key("vrchat", {{"trackers", Names{"1", "head"}}}, two), "accepted");
  EXPECT_EQ(refused_key("vrchat", {{"trackers", Names{"8", "9"}}}, two), "trackers[2]");
  EXPECT_EQ(refused_key("vrchat", {{"trackers", Names{"0", "1"}}}, two), "trackers[1]");
  EXPECT_EQ(refused_key("vrchat", {{"trackers", Names{"Head", "1"}}}, two), "trackers[1]");
  EXPECT_EQ(refused_key("vrchat", {{"trackers", Names{"2", "2"}}}, two), "trackers[2]");
  EXPECT_EQ(refused_key("vrchat", {{"trackers", Names{"1"}}}, two), "trackers");
  EXPECT_EQ(refused_key("vrchat", {}, two), "accepted");  // 1 and 2
  std::vector<OutputStream> nine;
  for (std::uint32_t i = 1; i <= 9; ++i) nine.push_back({i, "s"});
  EXPECT_EQ(refused_key("vrchat", {}, nine), "trackers");
}

// --- max_rate_hz ------------------------------------------------------------------------------

TEST(OutputRateLimit, PassesAtMostTheRatePerStream) {
  OutputRateLimit limit(100.0, 2);
  int passed = 0;
  for (int i = 0; i < 1000; ++i) passed += limit.admit(0, i * 0.001, i > 0 ? 0.001 : 0.0);  // 1 kHz for 1 s
  EXPECT_EQ(passed, 100);
  EXPECT_TRUE(limit.admit(1, 0.0005, 0.0));  // the other stream has its own clock
  EXPECT_TRUE(limit.admit(0, 0.0, 0.001));   // time went back (a restarted replay): starts over
  OutputRateLimit none(0.0, 1);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(none.admit(0, 1.0, 0.0));
}

TEST(OutputRateLimit, SamplesStampedInClumpsPassAtTheRateTheyWereTakenAt) {
  // 250 Hz read every 16 ms: four samples stamped 1 µs apart per read, each sampled step one
  // interval (SampleGate). At most 100 Hz passes every third sample (12 ms of sample time
  // apart), 83 a second, as for the same stream evenly stamped. By the stamps only the first
  // of each read would pass, 62 a second, and always the stalest.
  OutputRateLimit clumped(100.0, 1), even(100.0, 1);
  std::vector<int> passed_clumped, passed_even;
  for (int i = 0; i < 1000; ++i) {  // 4 s
    const double stamp = 0.016 * (i / 4) + 1e-6 * (i % 4);
    const double step = i > 0 ? 0.004 : 0.0;
    if (clumped.admit(0, stamp, step)) passed_clumped.push_back(i);
    if (even.admit(0, 0.004 * i, step)) passed_even.push_back(i);
  }
  EXPECT_EQ(passed_even.size(), 334u);
  ASSERT_GE(passed_clumped.size(), 330u);
  EXPECT_LE(passed_clumped.size(), 334u);
  for (std::size_t k = 2; k < passed_clumped.size(); ++k)
    EXPECT_EQ(passed_clumped[k] - passed_clumped[k - 1], 3) << "at sample " << passed_clumped[k];
}

}  // namespace
}  // namespace posefair::daemon
