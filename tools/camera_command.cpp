#include "camera_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <utility>

#include "camera_keyframe_file.hpp"
#include "posefair/core/error.hpp"
#include "posefair/core/matrix_interpolation_study.hpp"

namespace posefair::tools {
namespace {

enum class OutputFormat { Csv, Json };

struct CameraOptions {
  std::string input;
  std::string output;  // empty: stdout
  InterpolationMethod method = InterpolationMethod::Subdivision;
  OutputFormat format = OutputFormat::Csv;
  std::optional<int> frames;
  bool precise = false;
  std::string study_dir;
  int study_matrices = 100;
  int study_pairs = 100;
  int study_batches = 20;
};

const char* method_name(InterpolationMethod m) {
  switch (m) {
    case InterpolationMethod::Linear: return "linear";
    case InterpolationMethod::Approximating: return "approximating";
    case InterpolationMethod::Subdivision: return "subdivision";
  }
  return "?";
}

// Frame times: every whole time from the first key to the last, or `frames` evenly spaced.
std::vector<double> frame_times(const std::vector<CameraKeyframe>& keys, std::optional<int> frames) {
  const double t0 = keys.front().time, t1 = keys.back().time;
  std::vector<double> t;
  if (frames) {
    for (int i = 0; i < *frames; ++i) t.push_back(*frames == 1 ? t0 : t0 + (t1 - t0) * i / (*frames - 1));
  } else {
    for (double f = std::ceil(t0); f <= t1; f += 1.0) t.push_back(f);
    if (t.empty()) t.push_back(t0);
  }
  return t;
}

void write_csv(std::ostream& out, const std::vector<double>& times, const std::vector<Mat4>& m) {
  out << "frame,time";
  for (int i = 0; i < 16; ++i) out << ",m" << i / 4 << i % 4;
  out << "\n";
  char buf[64];
  for (std::size_t f = 0; f < m.size(); ++f) {
    std::snprintf(buf, sizeof buf, "%zu,%.17g", f, times[f]);
    out << buf;
    for (int i = 0; i < 16; ++i) {
      std::snprintf(buf, sizeof buf, ",%.17g", m[f](i / 4, i % 4));
      out << buf;
    }
    out << "\n";
  }
}

void write_json(std::ostream& out, InterpolationMethod method, const std::vector<double>& times,
                const std::vector<Mat4>& m) {
  char buf[64];
  out << "{\"method\":\"" << method_name(method) << "\",\"frames\":[";
  for (std::size_t f = 0; f < m.size(); ++f) {
    std::snprintf(buf, sizeof buf, "%.17g", times[f]);
    out << (f ? ",\n" : "\n") << "{\"frame\":" << f << ",\"time\":" << buf << ",\"matrix\":[";
    for (int r = 0; r < 4; ++r) {
      out << (r ? ",[" : "[");
      for (int c = 0; c < 4; ++c) {
        std::snprintf(buf, sizeof buf, "%.17g", m[f](r, c));
        out << (c ? "," : "") << buf;
      }
      out << "]";
    }
    out << "]}";
  }
  out << "\n]}\n";
}

int run_interpolation(const CameraOptions& o) {
  std::vector<CameraKeyframe> keys;
  try {
    keys = read_camera_keyframes(o.input);
  } catch (const std::ios_base::failure&) {
    std::cerr << "posefair camera: cannot open " << o.input << ": " << std::strerror(errno) << "\n";
    return exit_code(ErrorKind::NoInput);
  } catch (const KeyframeFileError& e) {
    std::cerr << "posefair camera: " << e.what() << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  std::vector<double> key_times;
  std::vector<CameraKey> camera_keys;
  for (const auto& k : keys) {
    key_times.push_back(k.time);
    camera_keys.push_back(k.key);
  }
  const std::vector<double> times = frame_times(keys, o.frames);
  const auto r = interpolate_cameras(o.method, key_times, camera_keys, times,
                                     o.precise ? CombinationOptions::precise() : CombinationOptions{});
  if (!r) {
    const MatrixError& e = r.error();
    std::cerr << "posefair camera: " << o.input;
    if (e.key >= 0) std::cerr << ":" << keys[e.key].line;
    std::cerr << ": ";
    if (e.key >= 0 && e.origin_key >= 0 && e.origin_key != e.key)
      std::cerr << "keyframe relative to the keyframe at line " << keys[e.origin_key].line << ": ";
    std::cerr << e.message << "\n";
    return exit_code(ErrorKind::DataErr);
  }
  std::ofstream file;
  if (!o.output.empty()) {
    file.open(o.output);
    if (!file) {
      std::cerr << "posefair camera: cannot create " << o.output << ": " << std::strerror(errno) << "\n";
      return exit_code(ErrorKind::CantCreate);
    }
  }
  std::ostream& out = o.output.empty() ? std::cout : file;
  if (o.format == OutputFormat::Csv)
    write_csv(out, times, r.value());
  else
    write_json(out, o.method, times, r.value());
  out.flush();
  if (!out) {
    std::cerr << "posefair camera: writing " << (o.output.empty() ? "stdout" : o.output) << " failed\n";
    return exit_code(ErrorKind::CantCreate);
  }
  return kExitOk;
}

// The Section 4.2 and 5.1 studies as CSV files for tools/plot_matrix_interpolation.py.
int run_study(const CameraOptions& o) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(o.study_dir, ec);
  auto open = [&](const char* name, std::ofstream& f) {
    f.open(fs::path(o.study_dir) / name);
    if (!f) std::cerr << "posefair camera: cannot create " << (fs::path(o.study_dir) / name).string() << "\n";
    return static_cast<bool>(f);
  };
  std::ofstream sq, lg, pl;
  if (!open("sqrt_iterations.csv", sq) || !open("log_square_roots.csv", lg) || !open("path_length.csv", pl))
    return exit_code(ErrorKind::CantCreate);
  const int n = o.study_matrices;
  sq << "matrix,iteration,residual,principal\n";
  for (const auto& r : sqrt_iteration_study(n, 12, 42))
    sq << r.matrix << "," << r.iteration << "," << r.residual << "," << r.principal << "\n";
  lg << "eps3,matrix,square_roots,distance_to_identity,series_terms,change,error\n";
  for (double eps3 : {1e-6, 1e-13})
    for (const auto& r : log_square_root_study(n, 30, eps3, eps3 < 1e-9, 42))
      lg << eps3 << "," << r.matrix << "," << r.square_roots << "," << r.distance_to_identity << "," << r.series_terms
         << "," << r.change << "," << r.error << "\n";
  pl << "draw,pair,drawn_angle_deg,rotation_deg,camera_parameter,camera_matrix,screen_parameter,screen_matrix,"
        "camera_vertices,screen_vertices\n";
  PathStudy paths[2];
  const std::pair<KeyPairDraw, const char*> draws[] = {{KeyPairDraw::UniformAngle, "uniform-angle"},
                                                       {KeyPairDraw::Independent, "independent"}};
  for (int d = 0; d < 2; ++d) {
    paths[d] = path_length_study(o.study_pairs, 42, draws[d].first);
    for (const auto& r : paths[d].pairs)
      pl << draws[d].second << "," << r.pair << "," << r.drawn_angle_deg << "," << r.rotation_deg << ","
         << r.camera_parameter << "," << r.camera_matrix << "," << r.screen_parameter << "," << r.screen_matrix << ","
         << r.camera_vertices << "," << r.screen_vertices << "\n";
  }
  for (const auto& [scales, name] : {std::pair{ScaleDraw::LogUniform, "log-uniform"}, std::pair{ScaleDraw::Uniform, "uniform"}}) {
    const auto big = large_rotation_study(1000, 42, scales);
    std::printf("section 3.2: %d transforms with rotations in [pi/2, pi], scales %s in [1e-2, 1e2]: %d have a negative\n"
                "             real eigenvalue (no real log), the bare square root fails on %d (%d of them with a principal\n"
                "             root); matrix_log succeeds on %d (%d hit a cap), worst relative error vs Eigen %.3g\n",
                big.matrices, name, big.negative_eigenvalue, big.sqrt_failed, big.sqrt_failed_without_negative, big.log_ok,
                big.log_root_cap, big.worst_log_error);
  }
  // The uniform-angle pairs by turn: how the excess grows with the angle.
  std::printf("section 5.1 (uniform-angle keys) by turn, camera space, mean excess parameter vs matrix:");
  for (int lo = 0; lo < 90; lo += 30) {
    double sp = 0.0, sm = 0.0;
    int count = 0;
    for (const auto& r : paths[0].pairs) {
      if (r.drawn_angle_deg < lo || r.drawn_angle_deg >= lo + 30) continue;
      sp += r.camera_parameter;
      sm += r.camera_matrix;
      ++count;
    }
    std::printf("  %d-%d deg (%d pairs) %.1f%% vs %.2f%%", lo, lo + 30, count, count ? sp / count : 0.0,
                count ? sm / count : 0.0);
  }
  std::printf("\n");
  // The paper's 130 of 1000: how much one batch of 1000 varies, with scales drawn uniformly.
  int fewest = 1000, most = 0;
  for (std::uint64_t batch = 1; batch <= static_cast<std::uint64_t>(o.study_batches); ++batch) {
    const int failed = large_rotation_study(1000, batch, ScaleDraw::Uniform).sqrt_failed;
    fewest = std::min(fewest, failed);
    most = std::max(most, failed);
  }
  if (o.study_batches > 0)
    std::printf("section 3.2: scales uniform, %d batches of 1000 (seeds 1-%d): the bare square root fails on %d to %d\n",
                o.study_batches, o.study_batches, fewest, most);
  for (int d = 0; d < 2; ++d) {
    const PathStudy& p = paths[d];
    std::printf("section 5.1 (%s keys): %zu keyframe pairs (%d rejected: rotation >= 90 deg); excess path, mean (median):\n"
                "             camera space: %.2f%% (%.2f%%) camera-parameter vs %.2f%% (%.2f%%) matrix, lower in %d pairs"
                " (%d vertex paths skipped)\n"
                "             screen:       %.2f%% (%.2f%%) camera-parameter vs %.2f%% (%.2f%%) matrix, lower in %d pairs"
                " (%d vertex paths skipped)\n",
                draws[d].second, p.pairs.size(), p.rejected_unsafe, p.camera.mean_parameter, p.camera.median_parameter,
                p.camera.mean_matrix, p.camera.median_matrix, p.camera.matrix_lower, p.camera_skipped,
                p.screen.mean_parameter, p.screen.median_parameter, p.screen.mean_matrix, p.screen.median_matrix,
                p.screen.matrix_lower, p.screen_skipped);
  }
  std::printf("wrote    %s/{sqrt_iterations,log_square_roots,path_length}.csv\n", o.study_dir.c_str());
  return (sq && lg && pl) ? kExitOk : exit_code(ErrorKind::CantCreate);
}

}  // namespace

void add_camera_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<CameraOptions>();
  auto* cmd = app.add_subcommand(
      "camera", "Interpolate camera keyframes by linear combination of matrices (Alexa; Hawkins & Grimm)");
  auto* input = cmd->add_option("keyframes", o->input, "keyframe file (format: docs/matrix-interpolation.md)");
  cmd->add_option("-o,--output", o->output, "file to write (default: standard output)");
  const std::map<std::string, InterpolationMethod> methods{{"linear", InterpolationMethod::Linear},
                                                           {"approximating", InterpolationMethod::Approximating},
                                                           {"subdivision", InterpolationMethod::Subdivision}};
  cmd->add_option("-m,--method", o->method,
                  "linear (eq. 3 per segment), approximating (C2 B-spline, eq. 8) or subdivision "
                  "(interpolating 4-point scheme; default)")
      ->transform(CLI::CheckedTransformer(methods, CLI::ignore_case));
  const std::map<std::string, OutputFormat> formats{{"csv", OutputFormat::Csv}, {"json", OutputFormat::Json}};
  cmd->add_option("--format", o->format, "csv (default) or json")
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case));
  cmd->add_option("-n,--frames", o->frames,
                  "number of frames evenly spaced from the first key to the last (default: one per whole time unit)")
      ->check(CLI::Range(1, 10000000));
  cmd->add_flag("--precise", o->precise,
                "tighter iteration constants (relative error ~1e-10 instead of the paper's ~1e-4)");
  auto* study = cmd->add_option("--study", o->study_dir,
                                "instead: run the Section 4.2 / 5.1 studies and write their CSV files to this directory")
                    ->excludes(input);
  cmd->add_option("--study-matrices", o->study_matrices, "study: random matrices per Section 4.2 study")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str()
      ->needs(study);
  cmd->add_option("--study-pairs", o->study_pairs, "study: random keyframe pairs for Section 5.1")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str()
      ->needs(study);
  cmd->add_option("--study-batches", o->study_batches,
                  "study: batches of 1000 large rotations (seeds 1..N) for Section 3.2's spread")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000))
      ->needs(study);
  cmd->callback([o, cmd, &exit_code] {
    if (!o->study_dir.empty()) {
      exit_code = run_study(*o);
      return;
    }
    if (o->input.empty()) {
      std::cerr << "posefair camera: a keyframe file is required\n" << cmd->help();
      exit_code = posefair::exit_code(ErrorKind::Usage);
      return;
    }
    exit_code = run_interpolation(*o);
  });
}

}  // namespace posefair::tools
