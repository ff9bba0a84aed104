#include "fair_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "posefair/core/error.hpp"
#include "posefair/core/causal_fairing.hpp"
#include "posefair/core/fairing.hpp"
#include "posefair/core/stream_rate.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {
namespace {

struct FairOptions {
  std::string input;
  std::string output;
  std::optional<formats::PoseFormat> format;
  std::string joint;
  bool skip_missing = false;
  bool quiet = false;
  FairingParams params;
  double eps_r_rotation = std::numeric_limits<double>::infinity();  // physical angle, rad
  // --causal: the real-time engine over the file.
  bool causal = false;
  WindowConfig window;
  std::optional<int> order;             // batch: the paper's 3; causal: the engine's default (2)
  std::optional<double> smoothing;      // μ for both rotation and position
  std::optional<int> window_iterations;
};

// Writes the result in the input's format; on failure says why and returns EX_CANTCREAT.
int write_output(const FairOptions& o, const formats::PoseFile& file, const PoseSequence& poses) {
  try {
    formats::write_pose_file(o.output, file, poses);
  } catch (const formats::PoseFileError& e) {
    std::cerr << "posefair fair: " << e.what() << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  return kExitOk;
}

void print_input_line(const FairOptions& o, const formats::PoseFile& file, const char* rate_kind, double rate) {
  const PoseSequence& in = file.poses();
  std::printf("input    %s: %zu samples, %s, %s, %.1f Hz %s rate", o.input.c_str(), in.size(),
              std::string(formats::to_string(file.format())).c_str(),
              in.has_position() ? "orientation + position" : "orientation only", rate, rate_kind);
  if (file.skipped_rows() > 0) std::printf(", %zu rows without orientation skipped", file.skipped_rows());
  std::printf("\n");
}

void print_deviation_line(double max_dist_r, bool with_position, double max_deviation_t) {
  std::printf("max dev  rotation %.6g rad (%.4g deg)", 2.0 * max_dist_r, 2.0 * max_dist_r * 180.0 / std::numbers::pi);
  if (with_position) std::printf(", position %.6g", max_deviation_t);
  std::printf("\n");
}

int run_causal(const FairOptions& o, const formats::PoseFile& file) {
  const PoseSequence& in = file.poses();
  WindowConfig c = o.window;
  c.epsilon_r = o.eps_r_rotation / 2.0;
  c.epsilon_t = o.params.epsilon_t;
  c.order = o.order.value_or(c.order);
  c.lambda_r = o.params.lambda_r;
  c.lambda_t = o.params.lambda_t;
  c.variant = o.params.variant;
  if (o.window_iterations) c.iterations = *o.window_iterations;
  // Unless --rate gives it, the engine measures the rate as it does for a live stream, and
  // follows it if it changes; the file's own rate is reported, and checks a --cutoff.
  const double rate = sample_rate(in.time);
  if (o.smoothing) c.smoothing_r = c.smoothing_t = *o.smoothing;
  try {
    WindowConfig at_file_rate = c;
    if (at_file_rate.rate_hz == 0.0) at_file_rate.rate_hz = rate;
    validate(at_file_rate);
    validate(c);  // as the engine will run it: an iterative solver's cutoff needs --rate
  } catch (const std::invalid_argument& e) {
    std::cerr << "posefair fair: " << e.what() << "\n";
    return exit_code(ErrorKind::Usage);
  }
  const auto t0 = std::chrono::steady_clock::now();
  const CausalResult r = fair_causal(in, c);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (const int rc = write_output(o, file, r.poses); rc != kExitOk) return rc;
  if (!o.quiet) {
    const char* solver = c.solver == WindowSolver::Linear ? "linear" : c.solver == WindowSolver::GaussNewton ? "gauss-newton" : "sweeps";
    print_input_line(o, file, "sample", rate);
    const EngineState st = r.state;
    std::printf("causal   m=%d, %s solver, window %d (%.3g s at %.4g Hz), lag %d (%.3g ms), horizon %.3g ms, continuity %g, bound per %s\n",
                c.order, solver, st.window, st.rate_hz > 0 ? st.window / st.rate_hz : 0.0, st.rate_hz, c.lag,
                st.rate_hz > 0 ? 1000.0 * c.lag / st.rate_hz : 0.0, 1e3 * c.horizon_s, c.continuity,
                c.bound == BoundPolicy::Sample ? "sample" : "window");
    auto channel = [&](const char* name, const ChannelAdaptation& a, const char* unit) {
      // The noise a rest is judged against, where the newest samples' has risen (docs/engine.md).
      char risen[48] = "";
      if (a.rest_noise > a.noise) std::snprintf(risen, sizeof risen, " (risen to %.3g lately)", a.rest_noise);
      if (a.adaptive)
        std::printf("%s adapted: noise %.3g %s%s, motion %.3g %s/s^%d, mu %.4g (cutoff %.3g Hz)%s%s at the end\n", name, a.noise,
                    unit, risen, a.motion, unit, c.order, a.smoothing, a.cutoff_hz,
                    a.noise_scale < 1.0 ? (", chosen for noise^2/" + std::to_string(std::lround(1.0 / a.noise_scale)) + " (predicted)").c_str() : "",
                    a.rest_averaged ? ", at rest, averaged over seconds," : a.at_rest ? ", at rest," : "");
      else
        std::printf("%s fixed: mu %.6g (cutoff %.3g Hz)\n", name, a.smoothing, a.cutoff_hz);
    };
    channel("rotation", st.rotation, "rad");
    if (in.has_position()) channel("position", st.position, "units");
    std::printf("samples  %llu emitted, %llu clamped to the bound, %llu restarts after gaps, changes of rate, of repeating or slerping (%llu for a "
                "change of rate), %llu dropped, %llu rejected\n",
                static_cast<unsigned long long>(r.counters.emitted), static_cast<unsigned long long>(r.counters.clamped),
                static_cast<unsigned long long>(r.counters.restarts), static_cast<unsigned long long>(r.counters.rate_changes),
                static_cast<unsigned long long>(r.gate.dropped()), static_cast<unsigned long long>(r.gate.rejected()));
    if (r.counters.lost > 0)
      std::printf("lost     %llu samples lost within a step of a few intervals (not a gap), stood in for on the line between "
                  "their neighbours and not emitted\n",
                  static_cast<unsigned long long>(r.counters.lost));
    if (r.counters.repeated > 0)
      std::printf("repeats  %llu samples repeated the measurement before them (a source read faster than it updates), "
                  "carried forward from the poses before; %s\n",
                  static_cast<unsigned long long>(r.counters.repeated),
                  st.repeating ? "the window holds the measurements alone, at the source's rate" : "not repeating at the end");
    if (r.counters.interpolated > 0)
      std::printf("slerped  %llu samples on the lines between measurements of a slower source (a slerped stream), "
                  "interpolated between the poses faired for %llu measurements found on them; %s\n",
                  static_cast<unsigned long long>(r.counters.interpolated),
                  static_cast<unsigned long long>(r.counters.slerp_measurements),
                  st.slerped ? "the window holds the measurements alone, at the source's rate" : "not slerped at the end");
    const double threshold = outlier_threshold(c);
    if (threshold > 0.0)
      std::printf("outliers %llu held at the prediction (threshold %g%s), %llu of them released as a motion's start\n",
                  static_cast<unsigned long long>(r.counters.held), threshold,
                  emits_held_as_measured(c) ? "; at lag 0 each emitted as measured, but the rest of a burst, and held for the poses after it" : "",
                  static_cast<unsigned long long>(r.counters.released));
    else
      std::printf("outliers not guarded (%s)\n", c.outlier_threshold ? "--outlier-threshold 0" : "an iterative solver at lag 0; --outlier-threshold turns the guard on");
    print_deviation_line(r.max_dist_r, in.has_position(), r.max_deviation_t);
    std::printf("cost     %.0f ns per sample\nwrote    %s\n", 1e9 * seconds / std::max<std::size_t>(1, in.size()), o.output.c_str());
  }
  return kExitOk;
}


int run_fair(FairOptions o) {
  {
    std::ifstream probe(o.input);
    if (!probe) {
      std::cerr << "posefair fair: cannot open " << o.input << ": " << std::strerror(errno) << "\n";
      return exit_code(ErrorKind::NoInput);
    }
  }
  formats::ReadOptions ro;
  ro.format = o.format;
  ro.bvh_joint = o.joint;
  ro.skip_missing = o.skip_missing;
  // The user's bound is a physical rotation angle; the paper's eq. 20 bounds dist on S³ (half).
  o.params.epsilon_r = o.eps_r_rotation / 2.0;
  if (o.order) o.params.order = *o.order;

  std::optional<formats::PoseFile> read;
  try {
    read.emplace(formats::read_pose_file(o.input, ro));
  } catch (const formats::PoseFileError& e) {
    std::cerr << "posefair fair: " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  const formats::PoseFile& file = *read;
  for (const std::string& w : file.warnings()) std::cerr << "posefair fair: warning: " << w << "\n";
  if (o.causal) return run_causal(o, file);
  const PoseSequence& in = file.poses();
  try {
    const FairingResult r = fair(in, o.params);
    if (const int rc = write_output(o, file, r.poses); rc != kExitOk) return rc;
    if (!o.quiet) {
      const int m = o.params.order;
      print_input_line(o, file, "sample", sample_rate(in.time));
      std::printf("fairing  m=%d, %s operators, lambda_r=%g lambda_t=%g, eps_r=%g rad eps_t=%g, cap %d\n", m,
                  o.params.variant == OperatorVariant::Printed ? "printed" : "corrected", o.params.lambda_r,
                  o.params.lambda_t, o.eps_r_rotation, o.params.epsilon_t, o.params.max_iterations);
      std::printf("stopped  after %d iterations: %s\n", r.iterations, std::string(to_string(r.stop)).c_str());
      std::printf("energy   E%d_r %.6g -> %.6g (x%.3g)", m, r.rotational_energy_before, r.rotational_energy_after,
                  r.rotational_energy_before > 0 ? r.rotational_energy_after / r.rotational_energy_before : 1.0);
      if (in.has_position())
        std::printf("   E%d_t %.6g -> %.6g (x%.3g)", m, r.translational_energy_before, r.translational_energy_after,
                    r.translational_energy_before > 0 ? r.translational_energy_after / r.translational_energy_before
                                                      : 1.0);
      std::printf("\n");
      print_deviation_line(r.max_dist_r, in.has_position(), r.max_deviation_t);
      std::printf("wrote    %s\n", o.output.c_str());
    }
    return kExitOk;
  } catch (const std::invalid_argument& e) {
    // Too few samples for the order (the parameters were checked by the command line).
    std::cerr << "posefair fair: " << o.input << ": " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
}

}  // namespace

void add_fair_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<FairOptions>();
  auto* cmd = app.add_subcommand("fair", "Batch Lee & Shin motion fairing of a pose file (TUM, CSV, BVH joint)");
  cmd->add_option("input", o->input, "pose file to read")->required();
  cmd->add_option("-o,--output", o->output, "file to write, in the input's format (written atomically)")->required();
  const std::map<std::string, formats::PoseFormat> formats{
      {"tum", formats::PoseFormat::Tum}, {"csv", formats::PoseFormat::Csv}, {"bvh", formats::PoseFormat::Bvh}};
  cmd->add_option("--format", o->format, "input format (default: by extension .txt/.tum, .csv, .bvh)")
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case));
  cmd->add_option("--joint", o->joint, "BVH: the joint to fair");
  cmd->add_flag("--skip-missing", o->skip_missing, "CSV: drop rows whose quaternion is nan or empty");
  cmd->add_option("-m,--order", o->order,
                  "fairing order m (2: constant angular velocity, 3: constant acceleration); default 3 for batch fairing (the "
                  "paper's), 2 with --causal (the engine's)")
      ->check(CLI::IsMember({2, 3}));
  cmd->add_option("--lambda-r", o->params.lambda_r, "rotational damping (slerp factor) in (0, 1]")
      ->check(CLI::Range(1e-9, 1.0))
      ->capture_default_str();
  cmd->add_option("--lambda-t", o->params.lambda_t, "translational damping in (0, 1]")
      ->check(CLI::Range(1e-9, 1.0))
      ->capture_default_str();
  cmd->add_option("--eps-r", o->eps_r_rotation,
                  "bound on each output's rotation from its measurement: physical angle, radians (default: none)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--eps-t", o->params.epsilon_t, "bound on each output's position offset, in the file's units (default: none)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("-n,--iterations", o->params.max_iterations, "cap on fairing sweeps")
      ->check(CLI::Range(0, 100000000))
      ->capture_default_str();
  cmd->add_option("--step-tolerance", o->params.step_tolerance,
                  "stop early when no sample moves more than this in a sweep (0: never)")
      ->check(CLI::NonNegativeNumber);
  const std::map<std::string, OperatorVariant> variants{{"corrected", OperatorVariant::Corrected},
                                                        {"printed", OperatorVariant::Printed}};
  cmd->add_option("--variant", o->params.variant, "rotation operators: corrected (default) or printed (the paper's as printed)")
      ->transform(CLI::CheckedTransformer(variants, CLI::ignore_case));
  cmd->add_flag("-q,--quiet", o->quiet, "print nothing on success");

  // The real-time engine, run over the file exactly as the daemon runs it (docs/engine.md).
  auto* causal = cmd->add_flag("--causal", o->causal, "run the real-time sliding-window engine instead of batch fairing");
  cmd->add_option("--window", o->window.window, "causal: window length W in samples (default: --window-time at the stream's rate)")
      ->check(CLI::Range(0, 4096))
      ->needs(causal);
  cmd->add_option("--window-time", o->window.window_s, "causal: the window as a time span, seconds")
      ->check(CLI::Range(1e-6, 60.0))
      ->capture_default_str()
      ->needs(causal);
  cmd->add_option("--rate", o->window.rate_hz, "causal: the stream's rate in Hz, fixed (default: measured from the first intervals and followed, as posefaird does)")
      ->check(CLI::NonNegativeNumber)
      ->needs(causal);
  cmd->add_option("--horizon", o->window.horizon_s, "causal: emit the pose predicted this many seconds past each sample (VR prediction)")
      ->check(CLI::Range(0.0, 1.0))
      ->needs(causal);
  cmd->add_option("--lag", o->window.lag, "causal: output lag L (samples; 0 = no added delay)")->capture_default_str()->needs(causal);
  const std::map<std::string, WindowSolver> solvers{{"linear", WindowSolver::Linear},
                                                    {"gauss-newton", WindowSolver::GaussNewton},
                                                    {"sweeps", WindowSolver::DampedSweeps}};
  cmd->add_option("--solver", o->window.solver, "causal: linear (default), gauss-newton, or sweeps (the paper's operators)")
      ->transform(CLI::CheckedTransformer(solvers, CLI::ignore_case))
      ->needs(causal);
  cmd->add_option("--window-iterations", o->window_iterations, "causal: Gauss-Newton iterations or damped sweeps per sample (default 1)")
      ->check(CLI::Range(0, 1000))
      ->needs(causal);
  auto* smoothing = cmd->add_option("--smoothing", o->smoothing,
                                    "causal: fixed smoothing weight mu of E_m against the data term (default: adapted to the stream)")
                        ->check(CLI::NonNegativeNumber)
                        ->needs(causal);
  cmd->add_option("--cutoff", o->window.cutoff_hz, "causal: fixed smoothing: mu for this half-gain frequency (Hz) at the stream's rate")
      ->check(CLI::PositiveNumber)
      ->excludes(smoothing)
      ->needs(causal);
  cmd->add_option("--continuity", o->window.continuity, "causal: weight kappa pulling the window toward poses already emitted")
      ->check(CLI::NonNegativeNumber)
      ->needs(causal);
  const std::map<std::string, BoundPolicy> bounds{{"sample", BoundPolicy::Sample}, {"window", BoundPolicy::Window}};
  cmd->add_option("--bound", o->window.bound, "causal: enforce eps per emitted sample (default) or on the whole window")
      ->transform(CLI::CheckedTransformer(bounds, CLI::ignore_case))
      ->needs(causal);
  cmd->add_option("--gap", o->window.gate.gap_threshold, "causal: a time step longer than this (s) restarts the window")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->needs(causal);
  cmd->add_option("--gap-intervals", o->window.gate.gap_intervals,
                  "causal: a time step longer than this many of the stream's intervals, beyond what catches up with samples stamped in a clump, also restarts the window (0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str()
      ->needs(causal);
  cmd->add_option("--outlier-threshold", o->window.outlier_threshold,
                  "causal: hold a lone sample this many times the median distance from the prediction of the ones before it (0: off; default 8, off for an iterative solver at lag 0)")
      ->check(CLI::Range(0.0, kMaxOutlierThreshold))
      ->needs(causal);
  cmd->callback([o, &exit_code] { exit_code = run_fair(*o); });
}

}  // namespace posefair::tools
