#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair reproduce lee-shin`: the Section 6 traces behind docs/fairing.md, as CSV.
void add_reproduce_command(CLI::App& app, int& exit_code);
}
