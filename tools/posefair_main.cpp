// posefair: the command-line tool. Each subcommand lives in its own <name>_command.cpp.
#include <CLI/CLI.hpp>

#include "bench_quality_command.hpp"
#include "devices_command.hpp"
#include "exit_codes.hpp"
#include "fair_command.hpp"
#include "registered_commands.hpp"
#include "reproduce_command.hpp"
#include "sub_command.hpp"

int main(int argc, char** argv) {
  CLI::App app{"posefair: smooth orientation streams with Lee & Shin motion fairing"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "posefair 0.1.0");
  int exit_code = posefair::tools::kExitOk;
  posefair::tools::add_fair_command(app, exit_code);
  posefair::tools::add_reproduce_command(app, exit_code);
  posefair::tools::add_bench_command(app, exit_code);
  posefair::tools::add_sub_command(app, exit_code);
  posefair::tools::add_devices_command(app, exit_code);
  posefair::tools::add_registered_commands(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints help or the error
    return rc == 0 ? 0 : posefair::tools::kExitUsage;
  }
  return exit_code;
}
