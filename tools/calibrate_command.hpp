#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair calibrate IN -o OUT`: magnetometer hard- and soft-iron calibration from a raw IMU
// recording turned through many orientations (docs/fusion.md).
void add_calibrate_command(CLI::App& app, int& exit_code);
}  // namespace posefair::tools
