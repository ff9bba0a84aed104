// posefair fuse, calibrate, bench fusion and bench gyro-fairing end to end: the real binary on the BROAD excerpt
// (tests/data/broad), on hand-made recordings (CSV and sample logs), and every bad-input case.
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "posefair/core/orientation_error.hpp"
#include "posefair/formats/imu_csv.hpp"
#include "posefair/formats/magnetometer_calibration_file.hpp"
#include "posefair/formats/pose_file.hpp"
#include "posefair/formats/sample_log.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::q;
using testing::run_posefair;
using testing::ScratchDir;
using testing::write_text;

const std::string kBroadFuseExcerpt = POSEFAIR_SOURCE_DIR "/tests/data/broad/07_undisturbed_fast_rotation_B.csv";
constexpr double kFuseTestDeg = M_PI / 180.0;

TEST(FuseCommand, FusesTheBroadExcerptCloseToTheOpticalReference) {
  ScratchDir dir;
  const auto out = dir / "fused.txt";
  const auto r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(out), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("fused 110 samples"));
  EXPECT_THAT(r.out, HasSubstr("0 non-finite"));
  const PoseSequence fused = formats::read_pose_file(out, {}).poses();
  const formats::ImuRecording rec = formats::read_imu_csv(kBroadFuseExcerpt);
  ASSERT_EQ(fused.size(), rec.samples.size());
  // The sensor rests here: the estimate levels at once; against the optical reference the
  // inclination is off by the IMU-to-marker misalignment only.
  double worst = 0.0;
  for (std::size_t k = 0; k < fused.size(); ++k) {
    EXPECT_DOUBLE_EQ(fused.time[k], rec.samples[k].time);
    if (!rec.samples[k].has_orientation()) continue;
    worst = std::max(worst, earth_frame_error(fused.orientation[k], rec.samples[k].orientation).inclination);
  }
  EXPECT_LT(worst / kFuseTestDeg, 1.5);
}

TEST(FuseCommand, OtherEstimators6DOptionsAndCsvOutput) {
  ScratchDir dir;
  const auto out = dir / "fused.csv";
  const auto r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(out) + " -e madgwick --6d --set beta=0.05", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("with madgwick (6D)"));
  std::ifstream in(out);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "t,qw,qx,qy,qz");
  EXPECT_EQ(formats::read_pose_file(out, {}).poses().size(), 110u);
}

TEST(FuseCommand, BadInputIsRefusedWithItsReason) {
  ScratchDir dir;
  const auto out = dir / "o.txt";
  auto r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(out) + " -e kalman", dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("unknown estimator 'kalman'; known: madgwick mahony vqf"));
  r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(out) + " --set bogus=1", dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("vqf has no option 'bogus'"));
  r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(out) + " -e madgwick --set beta=fast", dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("beta=fast: not a number"));
  r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(out) + " --set tau_acc=-1", dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("tau_acc: must be positive"));
  r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(dir / "o.bvh"), dir);
  EXPECT_EQ(r.exit_code, 64);
  r = run_posefair("fuse " + q(dir / "absent.csv") + " -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 66);
  write_text(dir / "poses.csv", "t,qw,qx,qy,qz\n0,1,0,0,0\n");
  r = run_posefair("fuse " + q(dir / "poses.csv") + " -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("poses.csv:1: missing columns"));
}

// A known motion as posefaird's recorder would log it: the sensor turns at a constant rate
// (in its own frame) from a tilted start, so its orientation at time t is
// q0 * exp(omega * t). Readings are exact: gravity and the earth's field (ENU) seen from
// the sensor. Stream 1 "optical" carries orientations only; stream 2 "imu" raw samples at
// 200 Hz for 4 s; with `second_imu`, stream 3 "wrist" raw samples too.
const Quat kLogStart = so3::from_rotation_vector(Vec3(0, 0, 30 * kFuseTestDeg)) * so3::from_rotation_vector(Vec3(20 * kFuseTestDeg, 0, 0));
const Vec3 kLogRate(0.3, -0.2, 0.8);  // rad/s, sensor frame
constexpr int kLogRawSamples = 800;

Quat logged_truth(double t) { return kLogStart * so3::from_rotation_vector(kLogRate * t); }

Sample raw_sample(std::uint32_t stream, std::uint64_t k) {
  Sample s;
  s.stream_id = stream;
  s.sequence = k;
  s.time = 0.005 * static_cast<double>(k);
  const Quat q = logged_truth(s.time);
  s.gyro = kLogRate;
  s.accel = q.conjugate() * Vec3(0, 0, 9.81);
  s.mag = q.conjugate() * Vec3(0, 20, -40);
  s.flags = kHasGyro | kHasAccel | kHasMag | kNoOrientation;
  return s;
}

std::filesystem::path write_motion_log(const ScratchDir& dir, bool second_imu = false) {
  formats::SampleLogHeader header;
  header.streams = {{1, "optical", "udp"}, {2, "imu", "serial:/dev/ttyUSB0 witmotion"}};
  if (second_imu) header.streams.push_back({3, "wrist", "serial:/dev/ttyUSB1 witmotion"});
  const auto path = dir / "motion.pflog";
  formats::SampleLogWriterOptions options;
  options.sync = false;
  formats::SampleLogWriter writer(path, header, options);
  for (int k = 0; k < kLogRawSamples; ++k) {
    if (k % 2 == 0) {
      Sample optical;
      optical.stream_id = 1;
      optical.sequence = static_cast<std::uint64_t>(k / 2);
      optical.time = 0.005 * k;
      optical.orientation = logged_truth(optical.time);
      writer.append(optical);
    }
    writer.append(raw_sample(2, static_cast<std::uint64_t>(k)));
    if (second_imu) writer.append(raw_sample(3, static_cast<std::uint64_t>(k)));
  }
  EXPECT_TRUE(writer.close());
  return path;
}

TEST(FuseCommand, FusesTheRawStreamOfASampleLogToTheKnownMotion) {
  ScratchDir dir;
  const auto log = write_motion_log(dir);
  const auto out = dir / "fused.txt";
  const auto r = run_posefair("fuse " + q(log) + " -o " + q(out), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("fused 800 samples of"));
  EXPECT_THAT(r.out, HasSubstr("stream 'imu' (id 2)"));
  const PoseSequence fused = formats::read_pose_file(out, {}).poses();
  ASSERT_EQ(fused.size(), static_cast<std::size_t>(kLogRawSamples));
  double worst = 0.0;
  for (std::size_t k = 0; k < fused.size(); ++k) {
    EXPECT_DOUBLE_EQ(fused.time[k], 0.005 * static_cast<double>(k));
    worst = std::max(worst, earth_frame_error(fused.orientation[k], logged_truth(fused.time[k])).total);
  }
  EXPECT_LT(worst / kFuseTestDeg, 0.5);  // exact readings: only the integration's rounding
  // The same stream named by id, 6D, CSV out: the same motion up to the free heading.
  const auto csv = dir / "fused.csv";
  ASSERT_EQ(run_posefair("fuse " + q(log) + " --stream 2 --6d -o " + q(csv), dir).exit_code, 0);
  const PoseSequence six_d = formats::read_pose_file(csv, {}).poses();
  ASSERT_EQ(six_d.size(), fused.size());
  EXPECT_LT(earth_frame_error(six_d.orientation.back(), logged_truth(six_d.time.back())).inclination / kFuseTestDeg, 0.5);
}

TEST(FuseCommand, ADamagedLogIsFusedUpToTheDamageWithAWarning) {
  ScratchDir dir;
  const auto log = write_motion_log(dir);
  std::filesystem::resize_file(log, std::filesystem::file_size(log) - 10);  // the last record cut short
  const auto r = run_posefair("fuse " + q(log) + " -o " + q(dir / "fused.txt"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: "));
  EXPECT_THAT(r.err, HasSubstr("truncated record"));
  EXPECT_THAT(r.out, HasSubstr("fused 799 samples"));
}

TEST(FuseCommand, ALogStreamThatCannotBeFusedIsRefusedNamingTheStreams) {
  ScratchDir dir;
  const auto log = write_motion_log(dir, /*second_imu=*/true);
  const auto out = dir / "o.txt";
  auto r = run_posefair("fuse " + q(log) + " -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("several streams have raw inertial samples; choose one with --stream: "
                               "'optical' (id 1): 0 raw samples of 400; 'imu' (id 2): 800 raw samples of 800; "
                               "'wrist' (id 3): 800 raw samples of 800"));
  EXPECT_FALSE(std::filesystem::exists(out));
  r = run_posefair("fuse " + q(log) + " --stream optical -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("stream 'optical' (id 1) has no raw inertial samples"));
  r = run_posefair("fuse " + q(log) + " --stream head -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("no stream 'head' in this log; streams: 'optical' (id 1)"));
  r = run_posefair("fuse " + q(log) + " --stream 7 -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_FALSE(std::filesystem::exists(out));
  r = run_posefair("fuse " + q(log) + " --stream wrist -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("stream 'wrist' (id 3)"));
  // A CSV has no streams.
  r = run_posefair("fuse " + q(kBroadFuseExcerpt) + " --stream imu -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("--stream applies to a sample log"));
  // A log with no raw samples at all, and a file named .pflog that is not one.
  {
    formats::SampleLogWriterOptions options;
    options.sync = false;
    formats::SampleLogWriter writer(dir / "poses.pflog", {1, {{1, "optical", "udp"}}}, options);
    Sample pose;
    pose.stream_id = 1;
    writer.append(pose);
    ASSERT_TRUE(writer.close());
  }
  r = run_posefair("fuse " + q(dir / "poses.pflog") + " -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("no stream has raw inertial samples"));
  write_text(dir / "text.pflog", "t_s,gyr_x\n");
  r = run_posefair("fuse " + q(dir / "text.pflog") + " -o " + q(out), dir);
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("not a posefair sample log"));
}

// Magnetometer readings with a known hard- and soft-iron distortion, in every direction.
std::vector<Vec3> distorted_readings() {
  std::mt19937 rng(9);
  std::normal_distribution<double> n;
  std::vector<Vec3> readings;
  for (int k = 0; k < 300; ++k) {
    const Vec3 f = Vec3(n(rng), n(rng), n(rng)).normalized() * 45.0;
    readings.emplace_back(1.2 * f.x() + 15.0, 0.9 * f.y() - 4.0, f.z() + 0.1 * f.x() + 22.0);
  }
  return readings;
}

// The readings as a CSV recording.
std::filesystem::path distorted_recording(const ScratchDir& dir) {
  std::string text = "t_s,gyr_x_rads,gyr_y_rads,gyr_z_rads,acc_x_ms2,acc_y_ms2,acc_z_ms2,mag_x_uT,mag_y_uT,mag_z_uT\n";
  int k = 0;
  for (const Vec3& m : distorted_readings()) {
    std::ostringstream line;
    line.precision(17);
    line << 0.01 * k++ << ",0,0,0,0,0,9.81," << m.x() << ',' << m.y() << ',' << m.z() << "\n";
    text += line.str();
  }
  write_text(dir / "turning.csv", text);
  return dir / "turning.csv";
}

TEST(CalibrateCommand, WritesACalibrationThatFuseApplies) {
  ScratchDir dir;
  const auto cal = dir / "mag.txt";
  const auto r = run_posefair("calibrate " + q(distorted_recording(dir)) + " -o " + q(cal), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("300 magnetometer readings"));
  const MagnetometerCalibration c = formats::read_magnetometer_calibration(cal);
  EXPECT_LT((c.offset - Vec3(15.0, -4.0, 22.0)).norm(), 1e-6);
  EXPECT_LT(c.residual_rms, 1e-6);
  const auto f = run_posefair("fuse " + q(kBroadFuseExcerpt) + " -o " + q(dir / "o.txt") + " --mag-calibration " + q(cal), dir);
  EXPECT_EQ(f.exit_code, 0) << f.err;
}

TEST(CalibrateCommand, ReadsTheMagnetometerOfASampleLogStream) {
  ScratchDir dir;
  const auto log = dir / "turning.pflog";
  {
    formats::SampleLogWriterOptions options;
    options.sync = false;
    formats::SampleLogWriter writer(log, {1, {{1, "optical", "udp"}, {4, "imu", "hid"}}}, options);
    std::uint64_t k = 0;
    for (const Vec3& m : distorted_readings()) {
      Sample s;
      s.stream_id = 4;
      s.sequence = k;
      s.time = 0.01 * static_cast<double>(k++);
      s.mag = m;
      s.flags = kHasMag | kNoOrientation;
      writer.append(s);
    }
    ASSERT_TRUE(writer.close());
  }
  const auto cal = dir / "mag.txt";
  const auto r = run_posefair("calibrate " + q(log) + " --stream imu -o " + q(cal), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("300 magnetometer readings"));
  EXPECT_LT((formats::read_magnetometer_calibration(cal).offset - Vec3(15.0, -4.0, 22.0)).norm(), 1e-6);
  const auto bad = run_posefair("calibrate " + q(log) + " --stream optical -o " + q(cal), dir);
  EXPECT_EQ(bad.exit_code, 65);
  EXPECT_THAT(bad.err, HasSubstr("stream 'optical' (id 1) has no raw inertial samples"));
}

TEST(CalibrateCommand, RefusesTooLittleMotion) {
  ScratchDir dir;
  const auto r = run_posefair("calibrate " + q(kBroadFuseExcerpt) + " -o " + q(dir / "mag.txt"), dir);  // the sensor rests
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr("turn the sensor"));
  EXPECT_FALSE(std::filesystem::exists(dir / "mag.txt"));
  EXPECT_EQ(run_posefair("calibrate " + q(dir / "absent.csv") + " -o " + q(dir / "mag.txt"), dir).exit_code, 66);
}

TEST(BenchFusionCommand, SaysWhereTheDataIsWhenItIsMissing) {
  ScratchDir dir;
  const auto r = run_posefair("bench fusion --data " + q(dir.path()), dir);
  EXPECT_EQ(r.exit_code, 66);
  EXPECT_THAT(r.err, HasSubstr("broad/trials.json not found; it comes from BROAD"));
  EXPECT_THAT(r.err, HasSubstr("POSEFAIR_DATA"));
}

TEST(BenchFusionCommand, ScoresATrialPerTrialAndPerGroup) {
  ScratchDir dir;
  std::filesystem::create_directories(dir / "data/broad");
  write_text(dir / "data/broad/trials.json",
             R"({"groups": [{"name": "all_trials"}, {"name": "fast"}],
                 "trials": {"07_undisturbed_fast_rotation_B": {"groups": ["all_trials", "fast"]},
                            "99_not_in_this_data_set": {"groups": ["all_trials"]}}})");
  // The excerpt with its movement flag set, so its tracked rows are scored.
  std::ifstream in(kBroadFuseExcerpt);
  std::string line, text;
  while (std::getline(in, line)) text += (text.empty() ? line : line.substr(0, line.size() - 1) + "1") + "\n";
  write_text(dir / "data/broad/07_undisturbed_fast_rotation_B.csv", text);
  const auto r = run_posefair("bench fusion --data " + q(dir / "data") + " -o " + q(dir / "out"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("# BROAD: 1 trials"));
  EXPECT_THAT(r.out, HasSubstr("| 07 | 5.00 |"));  // BROAD's published Madgwick figure beside ours
  EXPECT_THAT(r.out, HasSubstr("| fast | 1 |"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out/fusion-trials.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out/fusion-groups.csv"));
}

TEST(BenchGyroFairingCommand, SaysWhereTheDataIsWhenItIsMissing) {
  ScratchDir dir;
  const auto r = run_posefair("bench gyro-fairing --data " + q(dir.path()), dir);
  EXPECT_EQ(r.exit_code, 66);
  EXPECT_THAT(r.err, HasSubstr("not found; it comes from BROAD"));
  EXPECT_THAT(r.err, HasSubstr("POSEFAIR_DATA"));
}

TEST(BenchGyroFairingCommand, ScoresEachTrialAgainstFairingAloneAndOneEuroTunedOnTheOthers) {
  ScratchDir dir;
  std::filesystem::create_directories(dir / "data/broad");
  // The excerpt as two trials (One Euro is tuned on the other one), its movement flag set.
  std::ifstream in(kBroadFuseExcerpt);
  std::string line, text;
  while (std::getline(in, line)) text += (text.empty() ? line : line.substr(0, line.size() - 1) + "1") + "\n";
  write_text(dir / "data/broad/07_undisturbed_fast_rotation_B.csv", text);
  write_text(dir / "data/broad/02_undisturbed_slow_rotation_B.csv", text);
  const auto r = run_posefair("bench gyro-fairing --seeds 1 --data " + q(dir / "data") + " -o " + q(dir / "out"), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("# Gyro-aided fairing on BROAD: 2 trials, 1 seeds"));
  EXPECT_THAT(r.out, HasSubstr("## Jitter 0.5° RMS"));
  EXPECT_THAT(r.out, HasSubstr("## Jitter 1.0° RMS"));
  EXPECT_THAT(r.out, HasSubstr("| 07 |"));
  EXPECT_THAT(r.out, HasSubstr("mincutoff="));  // the One Euro configuration picked on the other trial
  EXPECT_THAT(r.out, HasSubstr("goal (every trial, both jitters): "));
  EXPECT_TRUE(std::filesystem::exists(dir / "out/gyro-fairing-trials.csv"));
}

}  // namespace
}  // namespace posefair
