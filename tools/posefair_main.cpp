// posefair: the command-line tool. Each subcommand lives in its own <name>_command.cpp and
// registers itself in tools/<name>.cmake (tools/CMakeLists.txt generates the list).
#include <CLI/CLI.hpp>

#include "posefair/core/error.hpp"
#include "registered_commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"posefair: smooth orientation streams with Lee & Shin motion fairing"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "posefair 0.1.0");
  int exit_code = posefair::kExitOk;
  posefair::tools::add_registered_commands(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints help or the error
    return rc == 0 ? 0 : posefair::exit_code(posefair::ErrorKind::Usage);
  }
  return exit_code;
}
