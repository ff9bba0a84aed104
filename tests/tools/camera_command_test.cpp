// `posefair camera` end to end: keyframe files in, camera matrices out, every bad-input case.
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "posefair/core/camera_matrix.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::run_posefair;
using testing::ScratchDir;

std::filesystem::path write_text(const ScratchDir& dir, const std::string& name, const std::string& text) {
  const auto p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// CSV rows "frame,time,m00..m33" -> matrices.
std::vector<Mat4> read_csv_matrices(const std::string& csv) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<Mat4> out;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string cell;
    std::getline(row, cell, ',');
    std::getline(row, cell, ',');
    Mat4 m;
    for (int i = 0; i < 16; ++i) {
      std::getline(row, cell, ',');
      m(i / 4, i % 4) = std::stod(cell);
    }
    out.push_back(m);
  }
  return out;
}

const char* kOrbit =
    "# three cameras orbiting the origin\n"
    "key 0  from 0 1 5        at 0 0 0  fov 50\n"
    "key 10 from 2.5 1 4.33   at 0 0 0  fov 40 cop 0.2 0   # 30 degrees on, COP moved\n"
    "\n"
    "key 20 from 4.33 1 2.5   at 0 0 0  fov 50 skew 0.1\n";

TEST(CameraCommand, WritesOneMatrixPerFrameThatHitsTheKeys) {
  ScratchDir dir;
  const auto in = write_text(dir, "orbit.txt", kOrbit);
  const auto out = dir / "frames.csv";
  const auto r = run_posefair("camera '" + in.string() + "' -o '" + out.string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto m = read_csv_matrices(testing::slurp(out));
  ASSERT_EQ(m.size(), 21u);
  CameraParams k0;
  k0.from = {0, 1, 5};
  k0.lens.fov_y = 50 * std::numbers::pi / 180;
  CameraParams k2 = k0;
  k2.from = {4.33, 1, 2.5};
  k2.lens.skew = 0.1;
  EXPECT_LT((m[0] - camera_matrix(k0)).norm(), 1e-6);
  EXPECT_LT((m[20] - camera_matrix(k2)).norm(), 1e-6);
}

TEST(CameraCommand, AllMethodsAndJsonOutput) {
  ScratchDir dir;
  const auto in = write_text(dir, "orbit.txt", kOrbit);
  for (const char* method : {"linear", "approximating", "subdivision"}) {
    const auto r = run_posefair("camera '" + in.string() + "' --method " + method + " --frames 7 --format json", dir);
    ASSERT_EQ(r.exit_code, 0) << method << r.err;
    EXPECT_THAT(r.out, HasSubstr(std::string("\"method\":\"") + method + "\""));
    EXPECT_THAT(r.out, HasSubstr("\"frame\":6,"));
    EXPECT_THAT(r.out, ::testing::Not(HasSubstr("\"frame\":7,")));
  }
}

TEST(CameraCommand, AcceptsMatrixKeyframes) {
  ScratchDir dir;
  const auto in = write_text(dir, "m.txt",
                             "key 0 matrix 1 0 0 0  0 1 0 0  0 0 1 -5  0 0 0 1\n"
                             "key 4 matrix 1 0 0 2  0 1 0 0  0 0 1 -5  0 0 0 1 near 1 far 10\n");
  const auto r = run_posefair("camera '" + in.string() + "' --method linear", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto m = read_csv_matrices(r.out);
  ASSERT_EQ(m.size(), 5u);
  EXPECT_NEAR(m[2](0, 3), 1.0, 1e-6);  // halfway between the two translations
}

struct BadCase {
  const char* text;
  const char* message;
};

TEST(CameraCommand, BadKeyframesNameFileAndLineAndExit65) {
  const BadCase cases[] = {
      {"key 0 from 0 0 5 at 0 0 0\nkey 1 from 0 0 5 at 0 0 5\n", ":2: from and at are the same point"},
      {"key 0 from 0 0 5 at 0 0 0 up 0 0 1\n", ":1: up is zero or parallel"},
      {"key 0 from 0 0 5 at 0 0 0\nkey 0 from 0 0 4 at 0 0 0\n", ":2: keyframe times must increase"},
      {"key 0 from 0 0 5 at 0 0 0 fov 200\n", ":1: fov must be in"},
      {"key 0 from 0 0 5 at 0 0 0 aspect -1\n", ":1: aspect must be positive"},
      {"key 0 from 0 0 5 at 0 0\n", ":1: missing at coordinate"},
      {"key 0 from 0 0 5 at 0 0 zero\n", ":1: bad at coordinate 'zero'"},
      {"key 0 frm 0 0 5\n", ":1: unknown field 'frm'"},
      {"camera 0\n", ":1: expected 'key'"},
      {"# nothing\n", "no keyframes"},
      {"key 0 matrix 1 0 0 0 0 1 0 0 0 0 0 0 0 0 0 1\n", ":1: the matrix is singular"},
      {"key 0 matrix 1 0 0 0 0 1 0 0 0 0 1 0 0 0 -1 0\n", ":1: the matrix must be affine"},
      {"key 0 matrix -1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n", ":1: the matrix mirrors"},
      // A half turn between keys: refused, naming the key and asking for another keyframe.
      {"key 0 from 0 0 5 at 0 0 0\n# comment\nkey 1 from 0 0 -5 at 0 0 0\n", ":3: keyframe relative to the keyframe at line 1"},
  };
  for (const auto& c : cases) {
    ScratchDir dir;
    const auto in = write_text(dir, "keys.txt", c.text);
    const auto r = run_posefair("camera '" + in.string() + "'", dir);
    EXPECT_EQ(r.exit_code, 65) << c.text << r.err;
    EXPECT_THAT(r.err, HasSubstr(in.string() + (c.message[0] == ':' ? "" : ": ") + c.message)) << c.text;
  }
}

TEST(CameraCommand, AHalfTurnAsksForAKeyframe) {
  ScratchDir dir;
  const auto in = write_text(dir, "k.txt", "key 0 from 0 0 5 at 0 0 0\nkey 1 from 5 0 -1 at 0 0 0\n");
  const auto r = run_posefair("camera '" + in.string() + "'", dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("add a keyframe"));
}

TEST(CameraCommand, UsageAndFileErrors) {
  ScratchDir dir;
  EXPECT_EQ(run_posefair("camera", dir).exit_code, 64);
  EXPECT_EQ(run_posefair("camera '" + (dir / "missing.txt").string() + "'", dir).exit_code, 66);
  const auto in = write_text(dir, "orbit.txt", kOrbit);
  EXPECT_EQ(run_posefair("camera '" + in.string() + "' -o '" + (dir / "no/such/dir.csv").string() + "'", dir).exit_code,
            73);
  EXPECT_EQ(run_posefair("camera '" + in.string() + "' --method cubic", dir).exit_code, 64);
}

TEST(CameraCommand, StudyWritesTheCsvFiles) {
  ScratchDir dir;
  const auto r = run_posefair("camera --study '" + (dir / "study").string() + "' --study-matrices 5 --study-pairs 5 --study-batches 1", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("section 5.1"));
  EXPECT_THAT(r.out, HasSubstr("1 batches of 1000"));
  for (const char* f : {"sqrt_iterations.csv", "log_square_roots.csv", "path_length.csv"})
    EXPECT_GT(testing::slurp(dir / "study" / f).size(), 50u) << f;
}

}  // namespace
}  // namespace posefair
