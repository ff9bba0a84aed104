#pragma once
// Runs the real `posefair` binary as a user would, capturing its exit status and output.
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

inline CliResult run_posefair(const std::string& args, const ScratchDir& dir) {
  const std::string bin = POSEFAIR_CLI_PROGRAM;
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = "'" + bin + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace posefair::testing
