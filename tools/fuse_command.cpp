// posefair fuse (docs/fusion.md): raw IMU CSV or a sample log stream in, orientation out.
#include "fuse_command.hpp"

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "estimator_option_text.hpp"
#include "fusion_run.hpp"
#include "posefair/core/error.hpp"
#include "posefair/formats/imu_recording_file.hpp"
#include "posefair/formats/magnetometer_calibration_file.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {

namespace {

struct FuseOptions {
  std::string input, output, estimator = "vqf", calibration, stream;
  std::vector<std::string> settings;
  bool six_d = false;
};

int run_fuse(const FuseOptions& o) {
  const OrientationEstimatorEntry* entry = find_orientation_estimator(o.estimator);
  if (entry == nullptr) {
    std::string known;
    for (const std::string& n : orientation_estimator_names()) known += " " + n;
    std::cerr << "posefair fuse: unknown estimator '" << o.estimator << "'; known:" << known << "\n";
    return exit_code(ErrorKind::Usage);
  }
  const auto out_format = formats::format_from_extension(o.output);
  if (!out_format || *out_format == formats::PoseFormat::Bvh) {
    std::cerr << "posefair fuse: " << o.output << ": the output must end in .txt or .tum (TUM) or .csv\n";
    return exit_code(ErrorKind::Usage);
  }
  std::unique_ptr<OrientationEstimator> estimator;
  try {
    OptionMap options = parse_estimator_settings(*entry, o.settings);
    if (o.six_d) options["magnetometer"] = false;
    estimator = entry->make(options);
  } catch (const std::invalid_argument& e) {
    std::cerr << "posefair fuse: --set " << e.what() << "\n";
    return exit_code(ErrorKind::Usage);
  }
  if (!std::filesystem::is_regular_file(o.input)) {
    std::cerr << "posefair fuse: cannot open " << o.input << "\n";
    return exit_code(ErrorKind::NoInput);
  }
  formats::ImuRecordingFile input;
  std::optional<MagnetometerCalibration> calibration;
  try {
    if (!o.calibration.empty()) calibration = formats::read_magnetometer_calibration(o.calibration);
    input = formats::read_imu_recording_file(o.input, o.stream);
  } catch (const Error& e) {
    std::cerr << "posefair fuse: " << e.what() << "\n";
    return e.exit_code();
  } catch (const std::exception& e) {
    std::cerr << "posefair fuse: " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  // A damaged log: what precedes the damage is good and is fused; the rest is named.
  for (const formats::SampleLogProblem& p : input.damage)
    std::cerr << "posefair fuse: warning: " << p.message << "; " << p.unread_bytes << " bytes after it not read\n";
  formats::ImuRecording& recording = input.recording;
  if (calibration)
    for (Sample& s : recording.samples)
      if (s.has_mag()) s.mag = calibration->apply(s.mag);
  const std::vector<Quat> estimate = run_estimator(*estimator, recording);

  PoseSequence poses;
  // Samples before the first accelerometer reading have no estimate: they are left out.
  std::size_t first = 0;
  while (first < recording.samples.size() && !recording.samples[first].has_accel()) ++first;
  for (std::size_t k = first; k < estimate.size(); ++k) {
    poses.time.push_back(recording.samples[k].time);
    poses.orientation.push_back(estimate[k]);
  }
  if (poses.size() == 0) {
    std::cerr << "posefair fuse: " << o.input << ": no accelerometer reading, so no orientation\n";
    return exit_code(ErrorKind::DataErr);
  }
  try {
    const formats::PoseFile file =
        *out_format == formats::PoseFormat::Csv ? formats::make_csv(poses) : formats::make_tum(poses);
    formats::write_pose_file(o.output, file, poses);
  } catch (const std::exception& e) {
    std::cerr << "posefair fuse: " << e.what() << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  std::cout << "fused " << poses.size() << " samples of " << o.input;
  if (input.from_sample_log) std::cout << ", stream " << input.stream << ",";
  std::cout << " with " << entry->name
            << (o.six_d ? " (6D)" : "") << " into " << o.output << "\n"
            << describe_estimator_state(estimator->state()) << "\n";
  return kExitOk;
}

}  // namespace

void add_fuse_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<FuseOptions>();
  auto* cmd = app.add_subcommand("fuse", "Orientation from raw gyroscope, accelerometer and magnetometer readings");
  cmd->add_option("input", o->input,
                  "raw IMU CSV (BROAD's columns: t_s, gyr_*, acc_*, mag_*; docs/fusion.md) or a sample log (.pflog, "
                  "posefaird's recording) with raw samples")
      ->required();
  cmd->add_option("--stream", o->stream,
                  "the log stream to fuse, by name or id (needed when several streams have raw samples)");
  cmd->add_option("-o,--output", o->output, "file to write: .txt/.tum (TUM) or .csv (t,qw,qx,qy,qz), sensor to ENU")
      ->required();
  cmd->add_option("-e,--estimator", o->estimator, "vqf, madgwick or mahony")->capture_default_str();
  cmd->add_flag("--6d", o->six_d, "leave the magnetometer out (heading free, drifts)");
  cmd->add_option("--set", o->settings, "an estimator option KEY=VALUE (docs/fusion.md lists them); repeatable");
  cmd->add_option("--mag-calibration", o->calibration, "a file written by posefair calibrate, applied to every magnetometer reading");
  cmd->callback([o, &exit_code] { exit_code = run_fuse(*o); });
}

}  // namespace posefair::tools
