// `posefair resample` end to end: the real binary on hand-made and real files, every bad-input case.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "posefair/core/pose_spline.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::run_posefair;
using testing::q;
using testing::ScratchDir;
using testing::write_text;

// A TUM file of 41 samples at 20 Hz: a smooth rotation and translation.
std::filesystem::path smooth_tum(const ScratchDir& dir) {
  std::string text = "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i <= 40; ++i) {
    const double t = 100.0 + 0.05 * i;
    const Quat r = so3::exp(Vec3(0.3 * std::sin(t), 0.2 * t, 0.1 * std::cos(2 * t)));
    char line[256];
    std::snprintf(line, sizeof line, "%.4f %.9f %.9f %.9f %.17g %.17g %.17g %.17g\n", t, std::sin(t), std::cos(t), 0.1 * t,
                  r.x(), r.y(), r.z(), r.w());
    text += line;
  }
  const auto path = dir / "smooth.txt";
  write_text(path, text);
  return path;
}

TEST(ResampleCommand, RateResamplingKeepsTheKnotsAndMatchesTheLibrary) {
  ScratchDir dir;
  const auto in = smooth_tum(dir);
  const auto out = dir / "out.txt";
  const auto r = run_posefair("resample " + q(in) + " -o " + q(out) + " --rate 100 --order 3 --manifold so3", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("41 samples"));
  EXPECT_THAT(r.out, HasSubstr("k=3"));
  EXPECT_THAT(r.out, HasSubstr("SO(3)"));
  const PoseSequence a = formats::read_pose_file(in, {}).poses();
  const PoseSequence b = formats::read_pose_file(out, {}).poses();
  ASSERT_EQ(b.size(), 201u);  // 2 s at 100 Hz, both ends included
  EXPECT_DOUBLE_EQ(b.time.front(), 100.0);
  EXPECT_NEAR(b.time.back(), 102.0, 1e-9);
  geometric_splines::PoseSplineOptions o;
  o.order = 3;
  o.manifold = geometric_splines::OrientationManifold::LieGroup;
  const PoseSequence expected = geometric_splines::resample(a, b.time, o);
  for (std::size_t i = 0; i < b.size(); ++i) {
    EXPECT_LT(so3::rotation_angle(b.orientation[i], expected.orientation[i]), 1e-12);
    EXPECT_LT((b.position[i] - expected.position[i]).norm(), 1e-12);
    if (i % 5 == 0) {  // every 5th output time is an input time
      EXPECT_LT(so3::rotation_angle(b.orientation[i], a.orientation[i / 5]), 1e-9);
      EXPECT_LT((b.position[i] - a.position[i / 5]).norm(), 1e-8);
    }
  }
}

TEST(ResampleCommand, TimesFileCsvOutputAndDerivatives) {
  ScratchDir dir;
  const auto in = smooth_tum(dir);
  const auto times = dir / "times.txt";
  write_text(times, "# wanted\n100.01\n\n100.5 extra fields are ignored\n101.25,x\n");
  const auto out = dir / "out.csv";
  const auto deriv = dir / "deriv.csv";
  const auto r = run_posefair("resample " + q(in) + " -o " + q(out) + " --times " + q(times) + " --order 1 --derivatives " +
                                  q(deriv) + " --velocity fit --fit-half-width 2",
                              dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string written = testing::slurp(out);
  EXPECT_EQ(written.substr(0, written.find('\n')), "t,qw,qx,qy,qz,px,py,pz");
  const PoseSequence b = formats::read_pose_file(out, {}).poses();
  ASSERT_EQ(b.size(), 3u);
  EXPECT_DOUBLE_EQ(b.time[2], 101.25);
  const std::string d = testing::slurp(deriv);
  EXPECT_EQ(d.substr(0, d.find('\n')), "t,wx,wy,wz,w_norm,ax,ay,az,a_norm");
  EXPECT_EQ(std::count(d.begin(), d.end(), '\n'), 4);
}

TEST(ResampleCommand, HoldoutOnRealOpticalTrackingBeatsGeodesicInterpolation) {
  // BROAD trial 07 (fast rotation, 285.7 Hz optical tracking): every 10th sample as a knot.
  // The bundled 7 s excerpt of it (data/demo/SOURCE.md).
  ScratchDir dir;
  const std::string data = POSEFAIR_SOURCE_DIR "/data/demo/broad-07-excerpt.csv";
  const auto r = run_posefair("resample '" + data + "' --skip-missing --holdout 10 --order 2", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  double spline_rms = 0, spline_max = 0, geo_rms = 0, geo_max = 0;
  ASSERT_EQ(std::sscanf(r.out.substr(r.out.find("spline   rotation")).c_str(), "spline   rotation rms %lf deg max %lf",
                        &spline_rms, &spline_max), 2) << r.out;
  ASSERT_EQ(std::sscanf(r.out.substr(r.out.find("geodesic rotation")).c_str(), "geodesic rotation rms %lf deg max %lf",
                        &geo_rms, &geo_max), 2) << r.out;
  EXPECT_GT(spline_rms, 0.0);
  EXPECT_LT(spline_rms, geo_rms) << r.out;
}

TEST(ResampleCommand, BadInputGetsClearErrorsAndSysexitsCodes) {
  ScratchDir dir;
  const auto in = smooth_tum(dir);
  const auto out = dir / "out.txt";
  // Non-increasing times in the pose file, reported with the file's line.
  const auto repeated = dir / "repeated.txt";
  write_text(repeated, "# c\n1.0 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n\n1.5 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n");
  auto r = run_posefair("resample " + q(repeated) + " -o " + q(out) + " --rate 10", dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr(repeated.string() + ":5: time 1.5 does not increase"));
  // Too few samples.
  const auto one = dir / "one.txt";
  write_text(one, "1.0 0 0 0 0 0 0 1\n");
  r = run_posefair("resample " + q(one) + " -o " + q(out) + " --rate 10", dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("at least 2"));
  // Requested times outside the data, then allowed with --clamp.
  const auto times = dir / "times.txt";
  write_text(times, "100.5\n# x\n102.5\n");
  r = run_posefair("resample " + q(in) + " -o " + q(out) + " --times " + q(times), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr(times.string() + ":3: time 102.5 is outside"));
  r = run_posefair("resample " + q(in) + " -o " + q(out) + " --times " + q(times) + " --clamp", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const PoseSequence clamped = formats::read_pose_file(out, {}).poses();
  const PoseSequence data = formats::read_pose_file(in, {}).poses();
  EXPECT_DOUBLE_EQ(clamped.time[1], 102.5);
  EXPECT_LT(so3::rotation_angle(clamped.orientation[1], data.orientation.back()), 1e-12);
  // Bad times files.
  write_text(times, "100.5\nabc\n");
  r = run_posefair("resample " + q(in) + " -o " + q(out) + " --times " + q(times), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr(times.string() + ":2: 'abc' is not a time"));
  write_text(times, "100.5\n100.5\n");
  r = run_posefair("resample " + q(in) + " -o " + q(out) + " --times " + q(times), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr(times.string() + ":2: time 100.5 does not increase"));
  r = run_posefair("resample " + q(in) + " -o " + q(out) + " --times " + q(dir / "missing.txt"), dir);
  EXPECT_EQ(r.exit_code, 66);
  // Missing input, malformed input, usage errors, unwritable output.
  r = run_posefair("resample " + q(dir / "none.txt") + " -o " + q(out) + " --rate 10", dir);
  EXPECT_EQ(r.exit_code, 66);
  const auto broken = dir / "broken.txt";
  write_text(broken, "1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n");
  r = run_posefair("resample " + q(broken) + " -o " + q(out) + " --rate 10", dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr(":2:"));
  EXPECT_EQ(run_posefair("resample " + q(in) + " -o " + q(out), dir).exit_code, 64);
  EXPECT_EQ(run_posefair("resample " + q(in) + " -o " + q(out) + " --rate 10 --holdout 3", dir).exit_code, 64);
  EXPECT_EQ(run_posefair("resample " + q(in) + " -o " + q(out) + " --rate 10 --order 0", dir).exit_code, 64);
  EXPECT_EQ(run_posefair("resample " + q(in) + " -o " + q(out) + " --rate -1", dir).exit_code, 64);
  EXPECT_EQ(run_posefair("resample " + q(in) + " -o " + q(out) + " --rate 10 --manifold r3", dir).exit_code, 64);
  r = run_posefair("resample " + q(in) + " -o " + q(dir / "no" / "such" / "dir.txt") + " --rate 10", dir);
  EXPECT_EQ(r.exit_code, 73);
}

}  // namespace
}  // namespace posefair
