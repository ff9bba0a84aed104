// posefair calibrate (docs/fusion.md): the magnetometer readings of a raw IMU CSV or sample log fitted with
// an ellipsoid; the calibration written as text for posefair fuse --mag-calibration.
#include "calibrate_command.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "posefair/core/error.hpp"
#include "posefair/core/magnetometer_calibration.hpp"
#include "posefair/formats/atomic_write.hpp"
#include "posefair/formats/imu_recording_file.hpp"
#include "posefair/formats/magnetometer_calibration_file.hpp"

namespace posefair::tools {

namespace {

struct CalibrateOptions {
  std::string input, output, stream;
};

int run_calibrate(const CalibrateOptions& o) {
  if (!std::filesystem::is_regular_file(o.input)) {
    std::cerr << "posefair calibrate: cannot open " << o.input << "\n";
    return exit_code(ErrorKind::NoInput);
  }
  std::vector<Vec3> readings;
  try {
    const formats::ImuRecordingFile input = formats::read_imu_recording_file(o.input, o.stream);
    for (const Sample& s : input.recording.samples)
      if (s.has_mag()) readings.push_back(s.mag);
    for (const formats::SampleLogProblem& p : input.damage)
      std::cerr << "posefair calibrate: warning: " << p.message << " (the readings before it are used)\n";
  } catch (const Error& e) {
    std::cerr << "posefair calibrate: " << e.what() << "\n";
    return e.exit_code();
  } catch (const std::exception& e) {
    std::cerr << "posefair calibrate: " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  MagnetometerCalibration cal;
  try {
    cal = fit_magnetometer_calibration(readings);
  } catch (const std::invalid_argument& e) {
    std::cerr << "posefair calibrate: " << o.input << ": " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  try {
    formats::write_file_atomically(o.output, formats::render_magnetometer_calibration(cal));
  } catch (const std::exception& e) {
    std::cerr << "posefair calibrate: " << e.what() << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  std::printf("%zu magnetometer readings of %s\n", readings.size(), o.input.c_str());
  std::printf("hard iron (offset): %.3f %.3f %.3f\n", cal.offset.x(), cal.offset.y(), cal.offset.z());
  std::printf("soft iron:          %.4f %.4f %.4f\n                    %.4f %.4f %.4f\n                    %.4f %.4f %.4f\n",
              cal.soft_iron(0, 0), cal.soft_iron(0, 1), cal.soft_iron(0, 2), cal.soft_iron(1, 0), cal.soft_iron(1, 1),
              cal.soft_iron(1, 2), cal.soft_iron(2, 0), cal.soft_iron(2, 1), cal.soft_iron(2, 2));
  std::printf("field strength %.3f, corrected norm RMS deviation %.3f (%.2f %%)\nwrote %s\n", cal.field_strength,
              cal.residual_rms, 100.0 * cal.residual_rms / cal.field_strength, o.output.c_str());
  return kExitOk;
}

}  // namespace

void add_calibrate_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<CalibrateOptions>();
  auto* cmd = app.add_subcommand("calibrate", "Magnetometer hard- and soft-iron calibration from a raw IMU recording");
  cmd->add_option("input", o->input,
                  "raw IMU CSV with mag_x/y/z columns, or a sample log (.pflog) with magnetometer readings, recorded "
                  "while turning the sensor every way")
      ->required();
  cmd->add_option("--stream", o->stream, "the log stream to read, by name or id (when several have raw samples)");
  cmd->add_option("-o,--output", o->output, "calibration file to write (for posefair fuse --mag-calibration)")->required();
  cmd->callback([o, &exit_code] { exit_code = run_calibrate(*o); });
}

}  // namespace posefair::tools
