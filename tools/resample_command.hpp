#pragma once
// `posefair resample`: a pose file resampled at a rate or at given times with the geometric
// C^k splines of Rodrigues, Silva Leite & Jakubiak (docs/splines.md).
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
void add_resample_command(CLI::App& app, int& exit_code);
}  // namespace posefair::tools
