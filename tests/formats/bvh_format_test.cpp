// BVH: hierarchy and motion parsing, one joint as the sequence, the real CMU and Boxing files
// (with their quirks), write-back of Euler angles nearest the original numbers, bad inputs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "pose_file_test_support.hpp"
#include "posefair/core/euler_angles.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// Excerpts of the real files, the hierarchy and the first frames (tests/data/bvh/README.md).
const std::string kCmu = POSEFAIR_SOURCE_DIR "/tests/data/bvh/01_01.bvh";
const std::string kBoxing = POSEFAIR_SOURCE_DIR "/tests/data/bvh/Boxing_Toes.bvh";
const std::string kSmall = POSEFAIR_SOURCE_DIR "/tests/formats/data/small.bvh";

ReadOptions joint(const std::string& name) {
  ReadOptions o;
  o.bvh_joint = name;
  return o;
}

PoseFileError bvh_error_of(const std::string& text, const ReadOptions& options) {
  return parse_error(text, "walk.bvh", options);
}

// Hand-written elementary rotations (degrees).
Eigen::Matrix3d rx(double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  Eigen::Matrix3d m;
  m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return m;
}
Eigen::Matrix3d ry(double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  Eigen::Matrix3d m;
  m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return m;
}
Eigen::Matrix3d rz(double deg) {
  const double a = deg * std::numbers::pi / 180.0;
  Eigen::Matrix3d m;
  m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return m;
}

std::vector<std::string_view> split(std::string_view text, std::string_view separators) {
  std::vector<std::string_view> parts;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t begin = text.find_first_not_of(separators, at);
    if (begin == std::string_view::npos) break;
    const std::size_t end = std::min(text.find_first_of(separators, begin), text.size());
    parts.push_back(text.substr(begin, end - begin));
    at = end;
  }
  return parts;
}

// Two documents token by token: equal text, or numbers within tol. Returns how many numbers
// differed in text.
std::size_t expect_same_numbers(const std::string& a, const std::string& b, double tol) {
  const std::vector<std::string_view> la = split(a, "\n"), lb = split(b, "\n");
  EXPECT_EQ(la.size(), lb.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < std::min(la.size(), lb.size()); ++i) {
    if (la[i] == lb[i]) continue;
    const std::vector<std::string_view> ta = split(la[i], " \t\r"), tb = split(lb[i], " \t\r");
    EXPECT_EQ(ta.size(), tb.size()) << "line " << i + 1;
    if (ta.size() != tb.size()) return differing;
    for (std::size_t t = 0; t < ta.size(); ++t) {
      if (ta[t] == tb[t]) continue;
      ++differing;
      const std::string sa(ta[t]), sb(tb[t]);
      char* end_a = nullptr;
      char* end_b = nullptr;
      const double va = std::strtod(sa.c_str(), &end_a);
      const double vb = std::strtod(sb.c_str(), &end_b);
      EXPECT_TRUE(*end_a == '\0' && *end_b == '\0') << "'" << sa << "' vs '" << sb << "'";
      EXPECT_NEAR(va, vb, tol) << "line " << i + 1 << " token " << t + 1;
      if (std::abs(va - vb) > tol) return differing;  // one report per document is enough
    }
  }
  return differing;
}

// The numbers of frame row k (0-based) of a document.
std::vector<double> frame_values(const std::string& text, std::size_t k) {
  std::istringstream in(text.substr(text.find("Frame Time:")));
  std::string line;
  std::getline(in, line);
  for (std::size_t i = 0; i <= k; ++i) std::getline(in, line);
  std::istringstream row(line);
  std::vector<double> values;
  for (double v; row >> v;) values.push_back(v);
  return values;
}

TEST(BvhFormat, ReadsTheSmallHandMadeFile) {
  const PoseFile root = read_pose_file(kSmall, joint("Hips"));
  EXPECT_EQ(root.format(), PoseFormat::Bvh);
  EXPECT_EQ(root.bvh_joints(), (std::vector<std::string>{"Hips", "Spine", "Leg"}));
  EXPECT_EQ(root.bvh_joint(), "Hips");
  EXPECT_TRUE(root.warnings().empty());
  const PoseSequence& p = root.poses();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p.time[0], 0.0);
  EXPECT_EQ(p.time[2], 2 * 0.04);
  ASSERT_TRUE(p.has_position());
  EXPECT_EQ(p.position[1], Vec3(1.5, 2.5, 3.5));
  // CHANNELS ... Zrotation Xrotation Yrotation: R = Rz Rx Ry.
  const Eigen::Matrix3d expected = rz(10.0) * rx(20.0) * ry(30.0);
  EXPECT_LT((p.orientation[0].toRotationMatrix() - expected).cwiseAbs().maxCoeff(), 1e-15);

  const PoseFile leg = read_pose_file(kSmall, joint("Leg"));
  EXPECT_FALSE(leg.poses().has_position());  // no position channels
  const Eigen::Matrix3d leg_expected = rx(89.0) * ry(43.0) * rz(-28.0);
  EXPECT_LT((leg.poses().orientation[2].toRotationMatrix() - leg_expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(BvhFormat, ReadsTheCmuFile) {
  const PoseFile f = read_pose_file(kCmu, joint("Hips"));
  EXPECT_EQ(f.bvh_joints().size(), 31u);
  EXPECT_EQ(f.bvh_joints()[1], "LHipJoint");
  EXPECT_TRUE(f.warnings().empty());
  const PoseSequence& p = f.poses();
  ASSERT_EQ(p.size(), 20u);  // frame 0 is the T-pose reference, kept as a sample
  EXPECT_EQ(p.time[10], 10 * 0.0083333);
  EXPECT_EQ(p.position[0], Vec3(9.3722, 17.8693, -17.3198));
  // Frame 0: the root has no rotation in the T-pose.
  EXPECT_LT(so3::rotation_angle(p.orientation[0], Quat::Identity()), 1e-15);
  // Frame 1, root "CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation":
  // 9.3722 17.8693 -17.3198 -3.2316 -7.5970 -2.0168.
  const Eigen::Matrix3d r = rz(-3.2316) * ry(-7.5970) * rx(-2.0168);
  EXPECT_LT(so3::rotation_angle(p.orientation[1], Quat(r)), 1e-14);
  EXPECT_LT((p.orientation[1].toRotationMatrix() - r).cwiseAbs().maxCoeff(), 1e-15);

  // A non-root joint: rotation only. LeftUpLeg is the third joint; its channels are values
  // 10..12 of each row (6 for Hips, 3 for LHipJoint before it). Frame 1: -13.8102 2.5002 3.3502.
  const PoseFile leg = read_pose_file(kCmu, joint("LeftUpLeg"));
  EXPECT_FALSE(leg.poses().has_position());
  EXPECT_LT(so3::rotation_angle(leg.poses().orientation[1],
                                Quat(rz(-13.8102) * ry(2.5002) * rx(3.3502))),
            1e-14);
}

TEST(BvhFormat, BoxingFileHasOneRowMoreThanItsHeaderSays) {
  TempDir dir;
  const PoseFile f = read_pose_file(kBoxing, joint("Hips"));
  EXPECT_EQ(f.bvh_joints().size(), 21u);
  EXPECT_EQ(f.poses().size(), 101u);
  EXPECT_EQ(f.poses().time[100], 100 * 0.01);
  ASSERT_EQ(f.warnings().size(), 1u);
  EXPECT_THAT(f.warnings()[0], HasSubstr("Boxing_Toes.bvh:"));
  EXPECT_THAT(f.warnings()[0], HasSubstr("Frames: says 100 but 101 frame rows follow"));

  // Written back, the header matches the rows; nothing else changes.
  const fs::path out = dir.path() / "boxing.bvh";
  write_pose_file(out, f, f.poses());
  const std::string original = slurp(kBoxing);
  const std::string written = slurp(out);
  EXPECT_THAT(original, HasSubstr("\nFrames:    100\n"));
  EXPECT_THAT(written, HasSubstr("\nFrames:    101\n"));
  const std::size_t at = original.find("100", original.find("Frames:"));
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(written, original.substr(0, at) + "101" + original.substr(at + 3));
  const PoseFile back = read_pose_file(out, joint("Hips"));
  EXPECT_TRUE(back.warnings().empty());
  EXPECT_EQ(back.poses().size(), 101u);
}

TEST(BvhFormat, UnchangedWriteIsByteIdentical) {
  TempDir dir;
  const PoseFile f = read_pose_file(kCmu, joint("LeftHand"));
  const fs::path out = dir.path() / "cmu.bvh";
  write_pose_file(out, f, f.poses());
  EXPECT_EQ(slurp(out), slurp(kCmu));
}

// q and -q are one rotation but different values, so every frame goes through the Euler
// solver; the nearest solution must give back the original numbers.
void expect_solver_reproduces(const std::string& file) {
  const ReadOptions any = joint("Hips");
  const std::string original = slurp(file);
  const PoseFile root = read_pose_file(file, any);
  std::size_t differing = 0;
  for (const std::string& name : root.bvh_joints()) {
    const PoseFile f = read_pose_file(file, joint(name));
    PoseSequence flipped = f.poses();
    for (Quat& q : flipped.orientation) q.coeffs() = -q.coeffs();
    const std::string written = render_pose_file(f, flipped);
    SCOPED_TRACE(file + " joint " + name);
    // The Boxing header count is corrected on write; compare the rest.
    std::string expected = original;
    if (!f.warnings().empty()) {
      const std::size_t at = expected.find("Frames:");
      const std::size_t eol = expected.find('\n', at);
      expected.replace(at, eol - at, "Frames: " + std::to_string(f.poses().size()));
    }
    differing += expect_same_numbers(expected, written, 1e-9);
    // And the values read back describe the same rotations.
    const PoseFile back = parse_pose_text(written, "back.bvh", joint(name));
    for (std::size_t k = 0; k < back.poses().size(); ++k)
      ASSERT_LT(so3::rotation_angle(back.poses().orientation[k], f.poses().orientation[k]), 1e-12);
  }
  // The solver really ran: many angles come back as longer text (e.g. 1.3272540000000002),
  // all within 1e-9 degrees (in practice within 1e-12) of the original numbers. (Over the
  // excerpts: about 1050 and 3000 of them; tests/data/bvh/README.md.)
  EXPECT_GT(differing, 100u);
}

TEST(BvhFormat, RewritingEveryJointOfTheCmuFileReproducesEveryNumber) { expect_solver_reproduces(kCmu); }

TEST(BvhFormat, RewritingEveryJointOfTheBoxingFileReproducesEveryNumber) {
  expect_solver_reproduces(kBoxing);
}

TEST(BvhFormat, SmallFileWithGimbalLockAndWrappedAnglesReproduces) {
  for (const char* name : {"Hips", "Spine", "Leg"}) {
    const PoseFile f = read_pose_file(kSmall, joint(name));
    PoseSequence flipped = f.poses();
    for (Quat& q : flipped.orientation) q.coeffs() = -q.coeffs();
    expect_same_numbers(slurp(kSmall), render_pose_file(f, flipped), 1e-9);
  }
}

TEST(BvhFormat, ChangedRotationsAndPositionsAreWrittenExactly) {
  const PoseFile f = read_pose_file(kSmall, joint("Hips"));
  PoseSequence changed = f.poses();
  const Quat turn = so3::from_rotation_vector(Vec3(0.0, 0.0, 10.0 * std::numbers::pi / 180.0));
  for (Quat& q : changed.orientation) q = turn * q;
  changed.position[0] = Vec3(-1.0, 0.125, 7.0);
  const std::string written = render_pose_file(f, changed);
  // Only the root's six channels changed; the other joints' values are as they were.
  EXPECT_THAT(written, HasSubstr("\n-1 0.125 7 "));
  EXPECT_THAT(written, HasSubstr(" -5.5 0 12.25 90.0 45.0 -30.0\n"));
  // Root rotation Rz(10°)·Rz(10)Rx(20)Ry(30) = Rz(20)Rx(20)Ry(30): the first angle moves by 10.
  const std::vector<double> row0 = frame_values(written, 0);
  EXPECT_NEAR(row0[3], 20.0, 1e-9);
  EXPECT_NEAR(row0[4], 20.0, 1e-9);
  EXPECT_NEAR(row0[5], 30.0, 1e-9);
  // Frame 2 (190 -100 370) stays in its own branch of solutions: 200 -100 370.
  const std::vector<double> row2 = frame_values(written, 2);
  EXPECT_NEAR(row2[3], 200.0, 1e-9);
  EXPECT_NEAR(row2[4], -100.0, 1e-9);
  EXPECT_NEAR(row2[5], 370.0, 1e-9);
  const PoseFile back = parse_pose_text(written, "back.bvh", joint("Hips"));
  for (std::size_t k = 0; k < changed.size(); ++k)
    EXPECT_LT(so3::rotation_angle(back.poses().orientation[k], changed.orientation[k]), 1e-13);
  EXPECT_EQ(back.poses().position[0], changed.position[0]);
  EXPECT_EQ(back.poses().position[1], f.poses().position[1]);
}

TEST(BvhFormat, ReportsBadInputWithFileAndLine) {
  const std::string small = slurp(kSmall);
  // Unknown joint: the message lists the joints.
  const PoseFileError unknown = bvh_error_of(small, joint("Head"));
  EXPECT_EQ(unknown.line(), 0u);
  EXPECT_EQ(unknown.message(), "no joint 'Head' in the hierarchy; joints: Hips, Spine, Leg");
  EXPECT_THAT(bvh_error_of(small, joint("")).what(),
              HasSubstr("walk.bvh:0: BVH needs a joint to read (ReadOptions::bvh_joint); joints: Hips, Spine, Leg"));

  // Wrong number of values in a motion row (line 29 is the second frame).
  std::string short_row = small;
  short_row.replace(short_row.find(" -29.0\n"), 6, "");
  const PoseFileError count = bvh_error_of(short_row, joint("Hips"));
  EXPECT_EQ(count.line(), 29u);
  EXPECT_EQ(count.message(), "expected 12 values per frame (the HIERARCHY's channels), found 11");

  std::string word = small;
  word.replace(word.find(" 13.25 "), 7, " 13.2x5 ");
  EXPECT_EQ(std::string(bvh_error_of(word, joint("Leg")).what()), "walk.bvh:29: field 9 '13.2x5' is not a number");

  std::string inf = small;
  inf.replace(inf.find(" 14.25 "), 7, " inf ");
  EXPECT_EQ(std::string(bvh_error_of(inf, joint("Leg")).what()), "walk.bvh:30: field 9 'inf' is not finite");

  std::string channel = small;
  channel.replace(channel.find("Xrotation Yrotation Zrotation"), 9, "Wrotation");
  EXPECT_THAT(bvh_error_of(channel, joint("Hips")).what(), HasSubstr("walk.bvh:18: unknown channel 'Wrotation'"));

  std::string no_motion = small.substr(0, small.find("MOTION"));
  EXPECT_THAT(bvh_error_of(no_motion, joint("Hips")).what(), HasSubstr("no MOTION section"));

  std::string unbalanced = small;
  unbalanced.erase(unbalanced.rfind('}'), 1);
  EXPECT_THAT(bvh_error_of(unbalanced, joint("Hips")).what(), HasSubstr("walk.bvh:25: unexpected end of HIERARCHY"));

  std::string no_rows = small.substr(0, small.find("1.0 2.0 3.0"));
  EXPECT_EQ(std::string(bvh_error_of(no_rows, joint("Hips")).what()), "walk.bvh:0: no samples (no frame rows after MOTION)");

  std::string bad_dt = small;
  bad_dt.replace(bad_dt.find("0.04"), 4, "0");
  EXPECT_EQ(std::string(bvh_error_of(bad_dt, joint("Hips")).what()), "walk.bvh:27: frame time '0' is not positive");

  EXPECT_EQ(std::string(bvh_error_of("", joint("Hips")).what()), "walk.bvh:0: empty file");

  // A joint without three rotation channels cannot be the sequence.
  std::string two = small;
  two.replace(two.find("CHANNELS 3 Zrotation Yrotation Xrotation"), 40, "CHANNELS 2 Zrotation Yrotation");
  two.replace(two.find(" 0 12.25"), 8, " 12.25");
  two.replace(two.find(" 90 13.25"), 9, " 13.25");
  two.replace(two.find(" 1.0 14.25"), 10, " 14.25");
  EXPECT_EQ(std::string(bvh_error_of(two, joint("Spine")).what()),
            "walk.bvh:6: joint 'Spine' has 2 rotation channel(s); it needs three, one per axis");
  EXPECT_EQ(parse_pose_text(two, "two.bvh", joint("Leg")).poses().size(), 3u);  // others still work
}

TEST(BvhFormat, FewerRowsThanTheHeaderSaysIsAWarning) {
  std::string text = slurp(kSmall);
  text.replace(text.find("Frames: 3"), 9, "Frames: 5");
  const PoseFile f = parse_pose_text(text, "five.bvh", joint("Spine"));
  EXPECT_EQ(f.poses().size(), 3u);
  ASSERT_EQ(f.warnings().size(), 1u);
  EXPECT_EQ(f.warnings()[0], "five.bvh:26: Frames: says 5 but 3 frame rows follow; using all 3");
  EXPECT_THAT(render_pose_file(f, f.poses()), HasSubstr("\nFrames: 3\n"));
}

}  // namespace
}  // namespace posefair::formats
