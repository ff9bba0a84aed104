#include "spline_command.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "posefair/core/error.hpp"
#include "keyframe_file.hpp"
#include "posefair/core/covariant_acceleration.hpp"
#include "posefair/core/quaternion_spline.hpp"
#include "posefair/core/sampled_rotation_energy.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {
namespace {

struct SplineCommandOptions {
  std::string input, output;
  std::optional<formats::PoseFormat> format;
  double rate = 100.0;
  std::optional<int> frames;
  std::optional<double> accuracy;
  std::string optimizer = "lbfgs";
  bool compare = false;
  std::string stages_csv, trace_csv;
  QuaternionSplineOptions spline;
};

// Output sample times: start, start + 1/rate, ..., and the last keyframe's time.
std::vector<double> sample_times(double start, double end, double rate) {
  std::vector<double> t = uniform_times(start, end, 1.0 / rate);
  if (end - t.back() > 1e-9 / rate) t.push_back(end);
  return t;
}

bool write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  return static_cast<bool>(f.flush());
}

std::string stages_table(const QuaternionSplineResult& r) {
  std::string s = "variable_frames,optimized,objective,covariant,seconds,evaluations,max_norm_deviation,max_el_deviation,mean_el_deviation\n";
  char line[256];
  for (const SplineStage& st : r.stages) {
    std::snprintf(line, sizeof line, "%d,%d,%.12g,%.12g,%.6g,%d,%.6g,%.6g,%.6g\n", st.variable_frames, st.optimized ? 1 : 0,
                  st.objective, st.covariant, st.seconds, st.evaluations, st.max_norm_deviation, st.max_el_deviation,
                  st.mean_el_deviation);
    s += line;
  }
  return s;
}

std::string trace_table(const QuaternionSplineResult& r, const std::vector<double>& times, double alpha) {
  std::string s = "t,norm_initial,norm_final,el_initial,el_final\n";
  char line[256];
  for (double t : times) {
    const CurveJet a = r.initial.curve.jet(t), b = r.spline.curve.jet(t);
    std::snprintf(line, sizeof line, "%.9g,%.12g,%.12g,%.9g,%.9g\n", t, a.q.norm(), b.q.norm(),
                  euler_lagrange_vector(a, alpha).norm(), euler_lagrange_vector(b, alpha).norm());
    s += line;
  }
  return s;
}

int run_spline(SplineCommandOptions o) {
  SplineKeyframes keys;
  try {
    keys = read_keyframes(o.input);
  } catch (const Error& e) {  // the file cannot be opened
    std::cerr << "posefair spline: " << e.what() << "\n";
    return e.exit_code();
  } catch (const formats::PoseFileError& e) {
    std::cerr << "posefair spline: " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  const std::size_t candidate_frames = (keys.time.size() - 1) * static_cast<std::size_t>(o.spline.segments_per_interval - 1);
  o.spline.variable_frames = o.frames ? *o.frames : o.accuracy ? static_cast<int>(candidate_frames) : 4;
  if (o.accuracy) o.spline.target_improvement = *o.accuracy;
  o.spline.optimizer.method = o.optimizer == "slsqp" ? SplineOptimizer::Slsqp : SplineOptimizer::Lbfgs;

  const auto t0 = std::chrono::steady_clock::now();
  const QuaternionSplineResult r = build_quaternion_spline(keys, o.spline);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const std::vector<double> times = sample_times(keys.time.front(), keys.time.back(), o.rate);
  PoseSequence poses;
  double raw_norm_deviation = 0.0;
  for (double t : times) {
    const Vec4 q = r.spline.curve.position(t);
    raw_norm_deviation = std::max(raw_norm_deviation, std::abs(q.norm() - 1.0));
    poses.time.push_back(t);
    poses.orientation.push_back(to_quat(q.normalized()));
  }
  const formats::PoseFormat format =
      o.format.value_or(formats::format_from_extension(o.output).value_or(formats::PoseFormat::Tum));
  try {
    const formats::PoseFile doc = format == formats::PoseFormat::Csv ? formats::make_csv(poses) : formats::make_tum(poses);
    formats::write_pose_file(o.output, doc, poses);
  } catch (const formats::PoseFileError& e) {
    std::cerr << "posefair spline: " << e.what() << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  if (!o.stages_csv.empty() && !write_text(o.stages_csv, stages_table(r))) {
    std::cerr << "posefair spline: cannot write " << o.stages_csv << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  if (!o.trace_csv.empty() && !write_text(o.trace_csv, trace_table(r, times, o.spline.alpha))) {
    std::cerr << "posefair spline: cannot write " << o.trace_csv << "\n";
    return exit_code(ErrorKind::CantCreate);
  }

  std::fprintf(stderr, "keys      %s: %zu keyframes over %.6g s, end angular velocities %s/%s\n", o.input.c_str(),
               keys.time.size(), keys.time.back() - keys.time.front(), keys.omega_start ? "given" : "free",
               keys.omega_end ? "given" : "free");
  std::fprintf(stderr, "settings  alpha %g, %d segments per interval, optimizer %s\n", o.spline.alpha,
               o.spline.segments_per_interval, std::string(to_string(o.spline.optimizer.method)).c_str());
  for (const SplineStage& st : r.stages)
    std::fprintf(stderr,
                 "stage     %-26s objective %.8g (covariant %.8g)  EL error mean %.4g max %.4g  max| |q|-1 | %.3g  "
                 "%.3f ms  %d evaluations\n",
                 !st.optimized              ? "unoptimised"
                 : st.variable_frames == 0  ? "velocities only"
                 : st.variable_frames == 1  ? "1 variable frame"
                                            : (std::to_string(st.variable_frames) + " variable frames").c_str(),
                 st.objective, st.covariant, st.mean_el_deviation, st.max_el_deviation, st.max_norm_deviation,
                 1e3 * st.seconds, st.evaluations);
  std::fprintf(stderr, "time      %.3f ms algorithm, %.3f ms with the statistics\n", 1e3 * r.stages.back().seconds, 1e3 * wall);
  std::fprintf(stderr, "norm      raw max | |q|-1 | %.3g at the output samples (samples written normalised)\n",
               raw_norm_deviation);
  if (o.compare && times.size() >= 3) {
    const double dt = 1.0 / o.rate;
    const auto ts = std::chrono::steady_clock::now();
    const std::vector<Quat> slerp = slerp_chain(keys.time, keys.orientation, uniform_times(keys.time.front(), keys.time.back(), dt));
    const double slerp_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
    std::vector<Quat> spline_samples;
    for (double t : uniform_times(keys.time.front(), keys.time.back(), dt)) spline_samples.push_back(to_quat(r.spline.curve.position(t)));
    std::fprintf(stderr, "compare   sampled covariant energy at %g Hz: spline %.8g, slerp chain %.8g (slerp sampling %.3f ms)\n",
                 o.rate, sampled_covariant_energy(spline_samples, dt), sampled_covariant_energy(slerp, dt), 1e3 * slerp_seconds);
  }
  std::fprintf(stderr, "wrote     %zu samples at %g Hz to %s\n", times.size(), o.rate, o.output.c_str());
  return kExitOk;
}

}  // namespace

void add_spline_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<SplineCommandOptions>();
  auto* cmd = app.add_subcommand("spline", "Minimal covariant-acceleration quaternion spline through keyframes (Ramamoorthi & Barr)");
  cmd->add_option("keyframes", o->input, "keyframe file: lines 't w x y z' or TUM lines, optional omega_start/omega_end")->required();
  cmd->add_option("-o,--output", o->output, "sampled curve to write (TUM, or CSV t,qw,qx,qy,qz)")->required();
  const std::map<std::string, formats::PoseFormat> formats{{"tum", formats::PoseFormat::Tum}, {"csv", formats::PoseFormat::Csv}};
  cmd->add_option("--format", o->format, "output format (default: .csv -> csv, else tum)")
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case));
  cmd->add_option("--rate", o->rate, "output samples per second")->check(CLI::Range(1e-6, 1e7))->capture_default_str();
  cmd->add_option("--alpha", o->spline.alpha, "weight of the soft unit-norm term")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--frames", o->frames, "variable frames to insert (default 4; with --accuracy: a cap)")
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--accuracy", o->accuracy,
                  "add variable frames one at a time until one lowers the objective by less than this fraction")
      ->check(CLI::Range(1e-12, 1.0));
  cmd->add_option("--frames-per-round", o->spline.frames_per_round,
                  "variable frames added per refinement round before re-optimising")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--segments", o->spline.segments_per_interval, "Euler-Lagrange segments per keyframe interval")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  cmd->add_option("--optimizer", o->optimizer, "lbfgs (default) or slsqp")
      ->transform(CLI::IsMember({"lbfgs", "slsqp"}, CLI::ignore_case));
  cmd->add_flag("--compare", o->compare, "also print the sampled covariant energy of the slerp chain through the keys");
  cmd->add_option("--stages-csv", o->stages_csv, "write the objective, timing and errors of every stage as CSV");
  cmd->add_option("--trace-csv", o->trace_csv, "write |q| and |EL| of the initial and final curve at the output samples as CSV");
  cmd->callback([o, &exit_code] { exit_code = run_spline(*o); });
}

}  // namespace posefair::tools
