#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair fuse IN -o OUT`: orientation from a raw IMU CSV (BROAD's columns) with a registered
// estimator, written as TUM or CSV quaternions (docs/fusion.md).
void add_fuse_command(CLI::App& app, int& exit_code);
}  // namespace posefair::tools
