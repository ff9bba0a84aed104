#pragma once
// Runs the real `posefair` binary (or a tool script) as a user would, capturing its exit status and output.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "../support/test_files.hpp"

namespace posefair::testing {

struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

// A path in single quotes for the shell command line of run_posefair (appended piecewise:
// GCC 12's -Wrestrict misfires on "'" + s + "'").
inline std::string q(const std::filesystem::path& p) {
  std::string quoted(1, '\'');
  quoted.append(p.string());
  quoted.push_back('\'');
  return quoted;
}

// Runs `program args` (args as on a shell command line), its stdout and stderr kept in dir.
inline CliResult run_program(const std::string& program, const std::string& args, const ScratchDir& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = "'" + program + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

inline CliResult run_posefair(const std::string& args, const ScratchDir& dir) { return run_program(POSEFAIR_CLI_PROGRAM, args, dir); }

}  // namespace posefair::testing
