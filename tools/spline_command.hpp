#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair spline`: minimal covariant-acceleration quaternion spline through keyframes
// (Ramamoorthi & Barr; docs/quaternion-splines.md), sampled at a fixed rate.
void add_spline_command(CLI::App& app, int& exit_code);
}
