#include "reproduce_command.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "posefair/core/error.hpp"
#include "posefair/core/fairing_study.hpp"

namespace posefair::tools {
namespace {

struct Run {
  const char* name;
  int order;
  double lambda_r;
  OperatorVariant variant;
};

// Figures 2–5 of the paper: m = 2 vs 3 at λ_r = 0.1; λ_r = 0.1/0.2/0.3 for m = 3 (and m = 2);
// the printed operators beside the corrected ones.
constexpr Run kRuns[] = {
    {"m2-l0.1", 2, 0.1, OperatorVariant::Corrected}, {"m2-l0.2", 2, 0.2, OperatorVariant::Corrected},
    {"m2-l0.3", 2, 0.3, OperatorVariant::Corrected}, {"m3-l0.1", 3, 0.1, OperatorVariant::Corrected},
    {"m3-l0.2", 3, 0.2, OperatorVariant::Corrected}, {"m3-l0.3", 3, 0.3, OperatorVariant::Corrected},
    {"m2-l0.1-printed", 2, 0.1, OperatorVariant::Printed}, {"m3-l0.1-printed", 3, 0.1, OperatorVariant::Printed},
};

int reproduce_lee_shin(const std::filesystem::path& out, int iterations, int seeds) {
  std::ofstream f(out);
  if (!f) {
    std::cerr << "posefair reproduce: cannot write " << out << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  f << "run,order,lambda_r,variant,iteration,mean_error_to_input,mean_error_to_truth,max_error_to_input,"
       "mean_angular_acceleration,mean_position_error_to_truth,mean_acceleration,rotational_energy\n";
  for (const Run& run : kRuns) {
    FairingParams p;
    p.order = run.order;
    p.lambda_r = run.lambda_r;
    p.variant = run.variant;
    p.max_iterations = iterations;
    const auto trace = mean_trace(SyntheticMotionSpec{}, seeds, p);
    for (const auto& t : trace) {
      char line[512];
      std::snprintf(line, sizeof line, "%s,%d,%.2f,%s,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", run.name, run.order,
                    run.lambda_r, run.variant == OperatorVariant::Printed ? "printed" : "corrected", t.iteration,
                    t.mean_error_to_input, t.mean_error_to_truth, t.max_error_to_input, t.mean_angular_acceleration,
                    t.mean_position_error_to_truth, t.mean_acceleration, t.rotational_energy);
      f << line;
    }
    const auto& last = trace.back();
    std::printf("%-16s after %4d sweeps: mean error to input %.4f, to truth %.4f (input %.4f) rad on S3\n", run.name,
                last.iteration, last.mean_error_to_input, last.mean_error_to_truth, trace.front().mean_error_to_truth);
  }
  f.close();
  if (!f) {
    std::cerr << "posefair reproduce: writing " << out << " failed\n";
    return exit_code(ErrorKind::CantCreate);
  }
  std::printf("wrote %s\n", out.c_str());
  return kExitOk;
}

}  // namespace

void add_reproduce_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("reproduce", "Reproduce a source paper's experiments as CSV (see docs/)");
  cmd->require_subcommand(1);
  auto* ls = cmd->add_subcommand("lee-shin", "Lee & Shin Section 6: error and acceleration vs iteration");
  auto out = std::make_shared<std::string>("lee-shin-section6.csv");
  auto iterations = std::make_shared<int>(1000);
  auto seeds = std::make_shared<int>(5);
  ls->add_option("-o,--output", *out, "CSV file to write")->capture_default_str();
  ls->add_option("--iterations", *iterations, "sweeps per run")->capture_default_str()->check(CLI::Range(1, 100000));
  ls->add_option("--seeds", *seeds, "random sequences averaged per run")->capture_default_str()->check(CLI::Range(1, 1000));
  ls->callback([=, &exit_code] { exit_code = reproduce_lee_shin(*out, *iterations, *seeds); });
}

}  // namespace posefair::tools
