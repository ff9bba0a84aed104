// CSV pose tables: columns by name, w-first or w-last, carried-through columns, missing
// samples, the real BROAD file, and bad inputs with file and line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include "pose_file_test_support.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

// An excerpt of BROAD trial 07: 10 rows the optical tracker lost, then 100 kept (tests/data/broad/README.md).
const std::string kBroad = POSEFAIR_SOURCE_DIR "/tests/data/broad/07_undisturbed_fast_rotation_B.csv";

ReadOptions csv() { return read_as(PoseFormat::Csv); }

PoseFileError csv_error_of(const std::string& text, const ReadOptions& options = csv()) {
  return parse_error(text, "walk.csv", options);
}

TEST(CsvFormat, WFirstAndWLastHeadersGiveTheSameQuaternions) {
  const PoseFile first = read_pose_file(kData + "small_wfirst.csv", {});
  const PoseFile last = read_pose_file(kData + "small_wlast.csv", {});
  expect_identical(first.poses(), last.poses());
  const PoseSequence& p = first.poses();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p.orientation[0].coeffs(), Quat::Identity().coeffs());
  EXPECT_NEAR(p.orientation[1].w(), std::sqrt(0.5), 1e-16);
  EXPECT_NEAR(p.orientation[1].x(), std::sqrt(0.5), 1e-16);
  EXPECT_EQ(p.orientation[1].y(), 0.0);
  EXPECT_EQ(p.position[2], Vec3(0.5, 0.25, 0.2));  // x,y,z in one file, px,py,pz in the other
  EXPECT_EQ(p.time[2], 0.02);

  // Any order of the four columns works; the names decide.
  const PoseFile shuffled =
      parse_pose_text("qz,timestamp,qx,qw,qy\n0.5,0,0.5,0.5,0.5\n", "s.csv", {});
  EXPECT_EQ(shuffled.poses().orientation[0].coeffs(), Quat(0.5, 0.5, 0.5, 0.5).coeffs());
  EXPECT_FALSE(shuffled.poses().has_position());
}

TEST(CsvFormat, OtherColumnsAreCarriedThroughUnchanged) {
  TempDir dir;
  const PoseFile f = read_pose_file(kData + "small_wfirst.csv", {});
  PoseSequence changed = f.poses();
  changed.orientation[0] = Quat(0.0, 0.0, 0.0, 1.0);
  changed.position[1].x() = -1.25;
  const fs::path out = dir.path() / "out.csv";
  write_pose_file(out, f, changed);
  EXPECT_EQ(slurp(out),
            "time,qw,qx,qy,qz,x,y,z,label\n"
            "0.0,0,0,0,1,0.5,0.25,0,\"a, quoted\"\n"
            "0.01,0.7071067811865476,0.7071067811865476,0,0,-1.25,0.25,0.1,b\n"
            "0.02,0.5,0.5,0.5,0.5,0.5,0.25,0.2,c\n");
  expect_identical(read_pose_file(out, {}).poses(), changed);

  // w-last layout written back w-last.
  const PoseFile last = read_pose_file(kData + "small_wlast.csv", {});
  EXPECT_THAT(render_pose_file(last, changed), HasSubstr("\n0.0,0,0,1,0,0.5,0.25,0\n"));
}

TEST(CsvFormat, PrefixedColumnsWithUnitsAndPrefixChoice) {
  const std::string text =
      "t_s,gt_qw,gt_qx,gt_qy,gt_qz,gt_px_m,gt_py_m,gt_pz_m,gyr_x_rads,gyr_y_rads,gyr_z_rads\n"
      "0,1,0,0,0,1,2,3,0.1,0.2,0.3\n";
  const PoseFile f = parse_pose_text(text, "b.csv", {});
  EXPECT_EQ(f.poses().position[0], Vec3(1, 2, 3));  // not the gyroscope columns

  const std::string two = "time,gt_qw,gt_qx,gt_qy,gt_qz,est_qx,est_qy,est_qz,est_qw\n0,1,0,0,0,0,0,1,0\n";
  EXPECT_THAT(csv_error_of(two).what(),
              HasSubstr("walk.csv:1: several quaternion column sets ('est_q*', 'gt_q*')"));
  ReadOptions est = csv();
  est.csv_prefix = "est_";
  EXPECT_EQ(parse_pose_text(two, "two.csv", est).poses().orientation[0].coeffs(),
            Quat(0, 0, 0, 1).coeffs());
}

TEST(CsvFormat, SkipMissingDropsRowsAndWritesOnlyTheKeptOnes) {
  const std::string text =
      "t,qw,qx,qy,qz,note\n"
      "0,1,0,0,0,first\n"
      "1,nan,nan,nan,nan,lost\n"
      "2,,0,0,0,empty\n"
      "3,1,0,0,0,last\n";
  EXPECT_EQ(csv_error_of(text).message(),
            "field 2 (qw) 'nan': quaternion is missing (ReadOptions::skip_missing drops such rows)");
  EXPECT_EQ(csv_error_of(text).line(), 3u);

  ReadOptions skip = csv();
  skip.skip_missing = true;
  const PoseFile f = parse_pose_text(text, "m.csv", skip);
  EXPECT_EQ(f.poses().size(), 2u);
  EXPECT_EQ(f.skipped_rows(), 2u);
  EXPECT_EQ(f.poses().time[1], 3.0);
  const std::string written = render_pose_file(f, f.poses());
  EXPECT_EQ(written, "t,qw,qx,qy,qz,note\n0,1,0,0,0,first\n3,1,0,0,0,last\n");

  // A nan position is still an error with skip_missing.
  EXPECT_THAT(csv_error_of("t,qw,qx,qy,qz,x,y,z\n0,1,0,0,0,nan,0,0\n", skip).what(),
              HasSubstr("walk.csv:2: field 6 (x) 'nan' is not finite"));
  // Nothing left at all.
  EXPECT_THAT(csv_error_of("t,qw,qx,qy,qz\n0,nan,0,0,0\n", skip).what(), HasSubstr("walk.csv:0: no samples"));
}

TEST(CsvFormat, KeepsByteOrderMarkAndCrLfLineEnds) {
  const std::string text = "\xEF\xBB\xBFt,qw,qx,qy,qz\r\n0,1,0,0,0\r\n1,nan,0,0,0\r\n2,1,0,0,0\r\n";
  ReadOptions skip = csv();
  skip.skip_missing = true;
  const PoseFile f = parse_pose_text(text, "crlf.csv", skip);
  ASSERT_EQ(f.poses().size(), 2u);
  PoseSequence changed = f.poses();
  changed.time[1] = 2.5;
  EXPECT_EQ(render_pose_file(f, changed), "\xEF\xBB\xBFt,qw,qx,qy,qz\r\n0,1,0,0,0\r\n2.5,1,0,0,0\r\n");
}

TEST(CsvFormat, ReadsTheRealBroadFileWithMissingSamples) {
  ReadOptions skip;
  skip.skip_missing = true;
  const PoseFile f = read_pose_file(kBroad, skip);
  const PoseSequence& p = f.poses();
  EXPECT_EQ(p.size(), 100u);  // of 110 rows; the optical tracker lost the marker in the others
  EXPECT_EQ(f.skipped_rows(), 110u - 100u);
  ASSERT_TRUE(p.has_position());
  for (std::size_t k = 1; k < p.size(); ++k) ASSERT_GT(p.time[k], p.time[k - 1]);
  for (const Quat& q : p.orientation) ASSERT_NEAR(q.norm(), 1.0, 1e-14);
  // 285.714 Hz (t = k · 0.0035, data rows 782-891 of the recording): the kept samples span
  // most of the excerpt's 0.3815 s.
  EXPECT_GE(p.time.front(), 781 * 0.0035 - 1e-9);
  EXPECT_LE(p.time.back(), 890 * 0.0035 + 1e-9);
  EXPECT_GT(p.time.back() - p.time.front(), 0.3);
  // Positions are in metres within a room.
  for (const Vec3& x : p.position) ASSERT_LT(x.norm(), 10.0);

  // Without skip_missing the first row (all nan) is the error.
  EXPECT_THAT([&] { read_pose_file(kBroad, {}); },
              ::testing::ThrowsMessage<PoseFileError>(HasSubstr("07_undisturbed_fast_rotation_B.csv:2: field 2 (gt_qw) 'nan'")));
}

TEST(CsvFormat, RealFileRoundTripsBitForBit) {
  TempDir dir;
  ReadOptions skip;
  skip.skip_missing = true;
  const PoseFile f = read_pose_file(kBroad, skip);
  PoseSequence changed = f.poses();
  for (std::size_t k = 0; k < changed.size(); k += 3)
    changed.orientation[k] = (changed.orientation[k] * so3::exp(Vec3(1e-3, 0, 2e-3))).normalized();
  const fs::path out = dir.path() / "broad.csv";
  write_pose_file(out, f, changed);
  const PoseFile back = read_pose_file(out, {});  // no missing rows are left
  EXPECT_EQ(back.skipped_rows(), 0u);
  expect_identical(back.poses(), changed);
  // The IMU columns after the eight pose columns are carried through as text, row for row.
  std::istringstream original(slurp(kBroad)), written(slurp(out));
  const auto tail = [](const std::string& line) {
    std::size_t at = 0;
    for (int i = 0; i < 8; ++i) at = line.find(',', at) + 1;
    return line.substr(at);
  };
  std::string a, b;
  std::size_t compared = 0;
  while (std::getline(original, a)) {
    if (a.find(",nan,") != std::string::npos) continue;
    ASSERT_TRUE(std::getline(written, b));
    ASSERT_EQ(tail(a), tail(b));
    ++compared;
  }
  EXPECT_FALSE(std::getline(written, b));
  EXPECT_EQ(compared, 101u);  // header + kept rows
}

TEST(CsvFormat, FreshFileRoundTrips) {
  PoseSequence p;
  p.time = {0.0, 0.5};
  p.orientation = {Quat::Identity(), so3::from_rotation_vector(Vec3(0.1, 0.2, 0.3))};
  p.position = {Vec3(1, 2, 3), Vec3(1.0 / 3.0, 0, -4)};
  CsvLayout layout;
  layout.w_first = false;
  layout.time_column = "time";
  layout.prefix = "est_";
  const std::string text = render_pose_file(make_csv(p, layout), p);
  EXPECT_THAT(text, HasSubstr("time,est_qx,est_qy,est_qz,est_qw,est_px,est_py,est_pz\n0,0,0,0,1,1,2,3\n"));
  expect_identical(parse_pose_text(text, "fresh.csv", {}).poses(), p);
}

TEST(CsvFormat, ReportsEveryBadInputWithFileAndLine) {
  struct Case {
    std::string text;
    std::size_t line;
    std::string message;
  };
  const std::string h = "t,qw,qx,qy,qz,x,y,z\n0,1,0,0,0,0,0,0\n";
  const Case cases[] = {
      {h + "1,1,0,abc,0,0,0,0\n", 3, "field 4 (qy) 'abc' is not a number"},
      {h + "abc,1,0,0,0,0,0,0\n", 3, "field 1 (t) 'abc' is not a number"},
      {h + "1,1,0,0,0,0,0\n", 3, "expected 8 fields as in the header, found 7"},
      {h + "1,0,0,0,0,0,0,0\n", 3, "zero quaternion"},
      {h + "1,2,0,0,0,0,0,0\n", 3, "non-unit quaternion: norm 2 differs from 1 by more than the tolerance 0.01"},
      {h + "-1,1,0,0,0,0,0,0\n", 3, "time goes backwards: -1 after 0"},
      {h + "1,1,0,0,0,inf,0,0\n", 3, "field 6 (x) 'inf' is not finite"},
      {h + "nan,1,0,0,0,0,0,0\n", 3, "field 1 (t) 'nan' is not finite"},
      {h + "1,1,nan,0,0,0,0,0\n", 3,
       "field 3 (qx) 'nan': quaternion is missing (ReadOptions::skip_missing drops such rows)"},
      {"", 0, "empty file"},
      {"t,qw,qx,qy,qz\n\n", 0, "no samples"},
  };
  for (const Case& c : cases) {
    const PoseFileError e = csv_error_of(c.text);
    EXPECT_EQ(e.line(), c.line) << c.text;
    EXPECT_EQ(e.message(), c.message) << c.text;
    EXPECT_EQ(std::string(e.what()), "walk.csv:" + std::to_string(c.line) + ": " + c.message);
  }
}

TEST(CsvFormat, MissingColumnsListWhatIsRequired) {
  const PoseFileError no_time = csv_error_of("a,qw,qx,qy,qz\n0,1,0,0,0\n");
  EXPECT_EQ(no_time.line(), 1u);
  EXPECT_THAT(no_time.message(), HasSubstr("missing time column; required: a time column (t, time, timestamp or t_s)"));
  EXPECT_THAT(no_time.message(), HasSubstr("header: a, qw, qx, qy, qz"));

  const PoseFileError no_qz = csv_error_of("\n\ntime,qw,qx,qy\n0,1,0,0\n");
  EXPECT_EQ(no_qz.line(), 3u);
  EXPECT_THAT(no_qz.message(), HasSubstr("missing quaternion column qz;"));
  EXPECT_THAT(no_qz.message(), HasSubstr("quaternion columns qw, qx, qy, qz"));

  const PoseFileError none = csv_error_of("time,value\n0,1\n");
  EXPECT_THAT(none.message(), HasSubstr("missing quaternion columns qw, qx, qy, qz;"));
  // An incomplete second set (gt_qw alone) is just another column.
  EXPECT_EQ(parse_pose_text("t,qw,qx,qy,qz,gt_qw\n0,1,0,0,0,7\n", "x.csv", {}).poses().size(), 1u);
}

}  // namespace
}  // namespace posefair::formats
