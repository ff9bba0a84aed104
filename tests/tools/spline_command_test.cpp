// `posefair spline` end to end: the real binary on keyframe files, every bad-input case.
#include <cmath>
#include <fstream>
#include <ostream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "posefair/core/quaternion_spline_example.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::run_posefair;
using testing::q;
using testing::ScratchDir;
using testing::write_text;

const std::string kExample = POSEFAIR_SOURCE_DIR "/docs/examples/quaternion-splines-7keys.txt";

TEST(QuaternionSplineCommand, ExampleFileIsTheCoreExample) {
  ScratchDir dir;
  const auto out = dir / "out.txt";
  const auto r = run_posefair("spline '" + kExample + "' -o " + q(out) + " --frames 0 --rate 1", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const SplineKeyframes k = seven_keyframe_example();
  const PoseSequence s = formats::read_pose_file(out, {}).poses();
  ASSERT_EQ(s.size(), 7u);  // one sample per second: exactly the keyframes
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_DOUBLE_EQ(s.time[i], k.time[i]);
    EXPECT_LT(so3::rotation_angle(s.orientation[i], k.orientation[i]), 1e-9);
  }
}

TEST(QuaternionSplineCommand, WritesTheSampledCurveAndReportsTheStages) {
  ScratchDir dir;
  const auto out = dir / "curve.txt", stages = dir / "stages.csv", trace = dir / "trace.csv";
  const auto r = run_posefair("spline '" + kExample + "' -o " + q(out) + " --rate 50 --frames 4 --compare --stages-csv " +
                                  q(stages) + " --trace-csv " + q(trace),
                              dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("velocities only"));
  EXPECT_THAT(r.err, HasSubstr("4 variable frames"));
  EXPECT_THAT(r.err, HasSubstr("EL error"));
  EXPECT_THAT(r.err, HasSubstr("ms"));
  EXPECT_THAT(r.err, HasSubstr("raw max"));
  EXPECT_THAT(r.err, HasSubstr("slerp chain"));
  const PoseSequence s = formats::read_pose_file(out, {}).poses();
  ASSERT_EQ(s.size(), 301u);  // 6 s at 50 Hz, both ends included
  const SplineKeyframes k = seven_keyframe_example();
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(s.orientation[i].norm(), 1.0, 1e-12);
    EXPECT_NEAR(s.orientation[i].z(), 0.0, 1e-12);
    if (i % 50 == 0) {
      EXPECT_LT(so3::rotation_angle(s.orientation[i], k.orientation[i / 50]), 1e-9) << i;
    }
    if (i > 0) {
      EXPECT_LT(so3::rotation_angle(s.orientation[i], s.orientation[i - 1]), 0.1);  // smooth, no jumps
    }
  }
  const std::string st = testing::slurp(stages);
  EXPECT_THAT(st, HasSubstr("variable_frames,optimized,objective"));
  EXPECT_EQ(std::count(st.begin(), st.end(), '\n'), 7);  // header + 6 stages
  const std::string tr = testing::slurp(trace);
  EXPECT_EQ(std::count(tr.begin(), tr.end(), '\n'), 302);
}

TEST(QuaternionSplineCommand, CsvOutputTumInputAndEndVelocities) {
  ScratchDir dir;
  const auto in = dir / "keys.tum", out = dir / "curve.csv";
  // TUM layout (w last), an end angular velocity, commas and comments.
  write_text(in,
             "# t tx ty tz qx qy qz qw\n"
             "0.0 1 2 3 0 0 0 1\n"
             "0.5, 0,0,0, 0.247403959255, 0, 0, 0.968912421711\n"
             "\n"
             "1.5 0 0 0 0.247403959255 0.247403959255 0 0.936848795\n"
             "omega_end 0 0 1\n");
  const auto r = run_posefair("spline " + q(in) + " -o " + q(out) + " --rate 10 --optimizer slsqp --alpha 500", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("optimizer slsqp"));
  EXPECT_THAT(r.err, HasSubstr("free/given"));
  const std::string text = testing::slurp(out);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,qw,qx,qy,qz");
  const PoseSequence s = formats::read_pose_file(out, {}).poses();
  ASSERT_EQ(s.size(), 16u);
  EXPECT_LT(so3::rotation_angle(s.orientation[5], Quat(0.968912421711, 0.247403959255, 0, 0)), 1e-9);
}

TEST(QuaternionSplineCommand, AccuracyAddsFramesUntilTheyStopPayingOff) {
  ScratchDir dir;
  const auto out = dir / "out.txt";
  const auto r = run_posefair("spline '" + kExample + "' -o " + q(out) + " --accuracy 0.001", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Frames 1..3 each lower the objective by more than 0.1 %, the 4th by 0.05 %: stop there.
  EXPECT_THAT(r.err, HasSubstr("4 variable frames"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("5 variable frames")));
}

struct BadFile {
  const char* name;
  const char* text;
  const char* expected;  // in the error message, after "<file>:"
};
// ctest shows the case by its name, not as bytes of pointers.
void PrintTo(const BadFile& f, std::ostream* os) { *os << f.name; }

class QuaternionSplineBadKeyframes : public ::testing::TestWithParam<BadFile> {};

TEST_P(QuaternionSplineBadKeyframes, ExitsWithDataErrorNamingFileAndLine) {
  ScratchDir dir;
  const auto in = dir / "keys.txt";
  write_text(in, GetParam().text);
  const auto r = run_posefair("spline " + q(in) + " -o " + q(dir / "out.txt"), dir);
  EXPECT_EQ(r.exit_code, 65) << r.err;
  std::ostringstream expected;  // "<file>:<line>: <message>"
  expected << in.string() << ':' << GetParam().expected;
  EXPECT_THAT(r.err, HasSubstr(expected.str()));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.txt"));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, QuaternionSplineBadKeyframes,
    ::testing::Values(
        BadFile{"non_increasing", "0 1 0 0 0\n1 1 0 0 0\n# c\n1 1 0 0 0\n", "4: time 1 does not increase"},
        BadFile{"decreasing", "0 1 0 0 0\n2 1 0 0 0\n1 1 0 0 0\n", "3: time 1 does not increase"},
        BadFile{"non_unit", "0 1 0 0 0\n1 0.9 0 0 0\n", "2: non-unit quaternion"},
        BadFile{"one_key", "# only one\n0 1 0 0 0\n", "2: fewer than two keyframes (found 1)"},
        BadFile{"no_key", "# nothing\n", "0: fewer than two keyframes (found 0)"},
        BadFile{"not_a_number", "0 1 0 0 0\n1 1 0 zero 0\n", "2: 'zero' is not a finite number"},
        BadFile{"field_count", "0 1 0 0 0\n1 1 0 0\n", "2: expected 5 fields"},
        BadFile{"mixed_layouts", "0 1 0 0 0\n1 0 0 0 0 0 0 1\n", "2: this keyframe has 8 fields"},
        BadFile{"omega", "0 1 0 0 0\nomega_end 1 2\n1 1 0 0 0\n", "2: omega_end needs three values"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(QuaternionSplineCommand, MissingInputAndBadOptions) {
  ScratchDir dir;
  auto r = run_posefair("spline " + q(dir / "nope.txt") + " -o " + q(dir / "out.txt"), dir);
  EXPECT_EQ(r.exit_code, 66);
  EXPECT_THAT(r.err, HasSubstr("nope.txt"));
  r = run_posefair("spline '" + kExample + "' -o " + q(dir / "out.txt") + " --optimizer newton", dir);
  EXPECT_EQ(r.exit_code, 64);
  r = run_posefair("spline '" + kExample + "' -o " + q(dir / "out.txt") + " --alpha -1", dir);
  EXPECT_EQ(r.exit_code, 64);
  r = run_posefair("spline '" + kExample + "' -o " + q(dir / "no-such-dir" / "out.txt"), dir);
  EXPECT_EQ(r.exit_code, 73);
}

}  // namespace
}  // namespace posefair
