#pragma once
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {
// `posefair fair`: batch Lee & Shin fairing of a pose file (docs/fairing.md).
void add_fair_command(CLI::App& app, int& exit_code);
}
