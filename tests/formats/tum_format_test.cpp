// TUM trajectories: reading excerpts of the real files (tests/data/tum), exact round trips, and every bad input
// reported with its file and line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "pose_file_test_support.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kRecorded = POSEFAIR_SOURCE_DIR "/tests/data/tum/";  // excerpts, see its README.md

ReadOptions tum() { return read_as(PoseFormat::Tum); }

PoseFileError tum_error_of(const std::string& text, const ReadOptions& options = tum()) {
  return parse_error(text, "walk.txt", options);
}

TEST(TumFormat, ReadsTheRealFiles) {
  struct Case {
    const char* file;
    std::size_t samples;
  };
  for (const Case& c : {Case{"fr2_desk_ORB.txt", 50}, Case{"fr2_desk_groundtruth.txt", 40},
                        Case{"freiburg1_xyz-groundtruth.txt", 50},
                        Case{"freiburg1_xyz-rgbdslam.txt", 50}}) {
    const PoseFile f = read_pose_file(kRecorded + c.file, {});  // .txt -> TUM
    EXPECT_EQ(f.format(), PoseFormat::Tum);
    EXPECT_EQ(f.poses().size(), c.samples) << c.file;
    EXPECT_TRUE(f.poses().has_position());
    for (const Quat& q : f.poses().orientation) ASSERT_NEAR(q.norm(), 1.0, 1e-14);
  }
  // First ground-truth line: 1311868163.8697 -0.1357 -1.4217 1.4764 0.6453 -0.5498 0.3363 -0.4101
  const PoseFile gt = read_pose_file(kRecorded + "fr2_desk_groundtruth.txt", {});
  const PoseSequence& p = gt.poses();
  EXPECT_EQ(p.time[0], 1311868163.8697);
  EXPECT_EQ(p.position[0], Vec3(-0.1357, -1.4217, 1.4764));
  const double n = std::sqrt(0.6453 * 0.6453 + 0.5498 * 0.5498 + 0.3363 * 0.3363 + 0.4101 * 0.4101);
  EXPECT_NEAR(p.orientation[0].w(), -0.4101 / n, 1e-15);  // w is the LAST column
  EXPECT_NEAR(p.orientation[0].x(), 0.6453 / n, 1e-15);
  EXPECT_NEAR(p.orientation[0].y(), -0.5498 / n, 1e-15);
  EXPECT_NEAR(p.orientation[0].z(), 0.3363 / n, 1e-15);
  // The file has one repeated timestamp (kept in the excerpt); equal consecutive times are accepted.
  std::size_t repeats = 0;
  for (std::size_t k = 1; k < p.size(); ++k) repeats += p.time[k] == p.time[k - 1];
  EXPECT_EQ(repeats, 1u);
}

TEST(TumFormat, UnchangedWriteIsByteIdenticalAndRereadsExactly) {
  TempDir dir;
  for (const char* file : {"fr2_desk_groundtruth.txt", "freiburg1_xyz-rgbdslam.txt"}) {
    const PoseFile f = read_pose_file(kRecorded + file, {});
    const fs::path out = dir.path() / file;
    write_pose_file(out, f, f.poses());
    EXPECT_EQ(slurp(out), slurp(kRecorded + file)) << file;
    expect_identical(read_pose_file(out, {}).poses(), f.poses());
  }
}

TEST(TumFormat, ChangedValuesRoundTripBitForBit) {
  TempDir dir;
  const PoseFile f = read_pose_file(kRecorded + "freiburg1_xyz-groundtruth.txt", {});
  PoseSequence changed = f.poses();
  for (std::size_t k = 0; k < changed.size(); ++k) {
    changed.orientation[k] =
        (changed.orientation[k] * so3::from_rotation_vector(Vec3(0.001 * std::sin(k), 0.002, -0.0007)))
            .normalized();
    changed.position[k] += Vec3(1.0 / 3.0, 0.1, -1e-7);
    changed.time[k] += 0.1;
  }
  const fs::path out = dir.path() / "changed.txt";
  write_pose_file(out, f, changed);
  const PoseFile back = read_pose_file(out, {});
  expect_identical(back.poses(), changed);
  // And once more: writing what was read back reproduces the same file.
  const fs::path again = dir.path() / "again.txt";
  write_pose_file(again, back, back.poses());
  EXPECT_EQ(slurp(again), slurp(out));
  // The comment lines are kept.
  EXPECT_THAT(slurp(out), HasSubstr("# timestamp tx ty tz qx qy qz qw\n"));
}

TEST(TumFormat, SkipsCommentsAndBlankLinesAndRenormalises) {
  const PoseFile f = read_pose_file(kData + "small.tum", {});
  const PoseSequence& p = f.poses();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p.time[1], 100.5);
  EXPECT_EQ(p.position[1], Vec3(1.0, -2.0, 0.25));
  EXPECT_NEAR(p.orientation[1].w(), std::sqrt(0.5), 1e-16);
  EXPECT_NEAR(p.orientation[1].z(), std::sqrt(0.5), 1e-16);
  EXPECT_EQ(p.orientation[2].coeffs(), Quat(0.5, 0.5, 0.5, 0.5).coeffs());

  // Slightly off unit (within the 1e-2 default tolerance): renormalised.
  const PoseFile off = parse_pose_text("1 0 0 0 0 0 0 1.005\n", "a.txt", tum());
  EXPECT_EQ(off.poses().orientation[0].w(), 1.0);
}

TEST(TumFormat, KeepsCrLfLineEnds) {
  const std::string text = "# c\r\n1 0 0 0 0 0 0 1\r\n2 0 0 0 0 0 0 1\r\n";
  const PoseFile f = parse_pose_text(text, "crlf.txt", {});
  PoseSequence changed = f.poses();
  changed.position[1] = Vec3(0.5, 0, 0);
  EXPECT_EQ(render_pose_file(f, changed), "# c\r\n1 0 0 0 0 0 0 1\r\n2 0.5 0 0 0 0 0 1\r\n");
}

TEST(TumFormat, FreshFileRoundTrips) {
  PoseSequence p;
  p.time = {0.0, 0.1, 0.1, 0.3};
  for (int k = 0; k < 4; ++k) p.orientation.push_back(so3::from_rotation_vector(Vec3(0.3 * k, -0.1, 0.2)));
  const std::string text = render_pose_file(make_tum(p), p);
  EXPECT_THAT(text, HasSubstr("# timestamp tx ty tz qx qy qz qw\n0 0 0 0 "));
  const PoseFile back = parse_pose_text(text, "fresh.tum", {});
  PoseSequence expected = p;
  expected.position.assign(4, Vec3::Zero());  // TUM always has positions
  expect_identical(back.poses(), expected);
}

TEST(TumFormat, ReportsEveryBadInputWithFileAndLine) {
  struct Case {
    std::string text;
    std::size_t line;
    std::string message;
  };
  const std::string ok = "# header\n1 0 0 0 0 0 0 1\n";
  const Case cases[] = {
      {ok + "2 0 0 abc 0 0 0 1\n", 3, "field 4 'abc' is not a number"},
      {ok + "2 0 0 1.5x 0 0 0 1\n", 3, "field 4 '1.5x' is not a number"},
      {ok + "2 0 0 0 0 0 1\n", 3, "expected 8 fields (timestamp tx ty tz qx qy qz qw), found 7"},
      {ok + "2 0 0 0 0 0 0 1 9\n", 3, "expected 8 fields (timestamp tx ty tz qx qy qz qw), found 9"},
      {ok + "2 0 0 0 0 0 0 0\n", 3, "zero quaternion"},
      {ok + "2 0 0 0 0 0 0 1.5\n", 3, "non-unit quaternion: norm 1.5 differs from 1 by more than the tolerance 0.01"},
      {ok + "\n0.5 0 0 0 0 0 0 1\n", 4, "time goes backwards: 0.5 after 1"},
      {ok + "2 nan 0 0 0 0 0 1\n", 3, "field 2 'nan' is not finite"},
      {ok + "2 0 0 0 0 0 0 inf\n", 3, "field 8 'inf' is not finite"},
      {"", 0, "empty file"},
      {"# only a comment\n\n", 0, "no samples"},
  };
  for (const Case& c : cases) {
    const PoseFileError e = tum_error_of(c.text);
    EXPECT_EQ(e.path(), "walk.txt");
    EXPECT_EQ(e.line(), c.line) << c.text;
    EXPECT_EQ(e.message(), c.message) << c.text;
    EXPECT_EQ(std::string(e.what()), "walk.txt:" + std::to_string(c.line) + ": " + c.message);
  }
  // Equal consecutive times are fine.
  EXPECT_EQ(parse_pose_text(ok + "1 0 0 0 0 0 0 1\n", "walk.txt", tum()).poses().size(), 2u);
  // A tighter tolerance turns a renormalisable quaternion into an error.
  ReadOptions strict = tum();
  strict.unit_tolerance = 1e-6;
  EXPECT_THAT(tum_error_of("1 0 0 0 0 0 0 1.001\n", strict).what(),
              HasSubstr("walk.txt:1: non-unit quaternion: norm 1.001"));
}

}  // namespace
}  // namespace posefair::formats
