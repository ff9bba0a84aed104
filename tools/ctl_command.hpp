#pragma once
// `posefair ctl`: ask a running posefaird through its control socket (docs/operations.md,
// "Control socket").
namespace CLI {
class App;
}  // namespace CLI

namespace posefair::tools {

void add_ctl_command(CLI::App& app, int& exit_code);

}  // namespace posefair::tools
