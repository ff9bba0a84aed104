#include "resample_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/core/pose_spline.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {
namespace {

namespace gs = geometric_splines;

struct ResampleOptions {
  std::string input;
  std::string output;
  std::optional<formats::PoseFormat> format;
  std::optional<formats::PoseFormat> output_format;
  bool skip_missing = false;
  std::optional<double> rate;
  std::string times_file;
  std::optional<int> holdout;
  bool clamp = false;
  std::string derivatives;
  bool quiet = false;
  gs::PoseSplineOptions spline;
  std::string manifold = "s3";
  std::string velocity = "bessel";
};

void apply_names(ResampleOptions& o) {
  auto lower = [](std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  o.spline.manifold = lower(o.manifold) == "so3" ? gs::OrientationManifold::LieGroup : gs::OrientationManifold::Sphere;
  const std::string v = lower(o.velocity);
  o.spline.velocity.estimator = v == "central" ? gs::KnotVelocityEstimator::CentralDifference
                                : v == "fit"   ? gs::KnotVelocityEstimator::LocalQuadraticFit
                                               : gs::KnotVelocityEstimator::Bessel;
}

// The 1-based line of the n-th data row (0-based) of a TUM or CSV file, 0 when unknown.
std::size_t data_line(const std::string& path, formats::PoseFormat format, std::size_t n) {
  std::ifstream in(path);
  std::string line;
  std::size_t number = 0, rows = 0;
  bool header_seen = format != formats::PoseFormat::Csv;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (format == formats::PoseFormat::Tum && line[first] == '#') continue;
    if (!header_seen) {
      header_seen = true;
      continue;
    }
    if (rows++ == n) return number;
  }
  return 0;
}

// Strictly increasing sample times, else an error naming the file and line.
void check_increasing(const ResampleOptions& o, const formats::PoseFile& file) {
  const auto& t = file.poses().time;
  if (t.size() < 2)
    throw Error{ErrorKind::DataErr, o.input + ": " + std::to_string(t.size()) +
                                         " sample(s); a spline needs at least 2"};
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) continue;
    const std::size_t line = o.skip_missing ? 0 : data_line(o.input, file.format(), i);
    std::ostringstream m;
    m.precision(17);
    m << o.input << ":" << (line ? std::to_string(line) : "sample " + std::to_string(i)) << ": time " << t[i]
      << " does not increase on the previous sample's " << t[i - 1] << " (the spline needs strictly increasing times)";
    throw Error{ErrorKind::DataErr, m.str()};
  }
}

std::vector<double> read_times(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error{ErrorKind::NoInput, "cannot open " + path + ": " + std::strerror(errno)};
  std::vector<double> times;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto end = line.find_first_of(" \t\r,", first);
    const std::string field = line.substr(first, end == std::string::npos ? std::string::npos : end - first);
    const std::string where = path + ":" + std::to_string(number) + ": ";
    double t = 0.0;
    std::size_t used = 0;
    try {
      t = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != field.size() || !std::isfinite(t)) throw Error{ErrorKind::DataErr, where + "'" + field + "' is not a time"};
    if (!times.empty() && !(t > times.back())) {
      std::ostringstream m;
      m.precision(17);
      m << where << "time " << t << " does not increase on the previous " << times.back();
      throw Error{ErrorKind::DataErr, m.str()};
    }
    times.push_back(t);
  }
  if (times.empty()) throw Error{ErrorKind::DataErr, path + ": no times"};
  return times;
}

std::vector<double> rate_times(double start, double end, double rate) {
  std::vector<double> times;
  // t_k = start + k / rate, computed from k (no accumulated rounding), up to end.
  const auto count = static_cast<std::size_t>(std::floor((end - start) * rate * (1.0 + 1e-12))) + 1;
  times.reserve(count);
  for (std::size_t k = 0; k < count; ++k) times.push_back(std::min(end, start + static_cast<double>(k) / rate));
  return times;
}

void write_derivatives(const std::string& path, const gs::PoseSpline& spline, const std::vector<double>& times) {
  std::ofstream out(path);
  if (!out) throw Error{ErrorKind::CantCreate, "cannot create " + path + ": " + std::strerror(errno)};
  out << "t,wx,wy,wz,w_norm,ax,ay,az,a_norm\n";
  out.precision(17);
  for (double t : times) {
    const double te = std::clamp(t, spline.start_time(), spline.end_time());
    // Body frame (as a gyroscope measures): R^T w and R^T w_dot.
    const Quat q = spline.evaluate(te).orientation;
    const Vec3 w = q.conjugate() * spline.angular_velocity(te);
    const Vec3 a = q.conjugate() * spline.angular_acceleration(te);
    out << t << ',' << w.x() << ',' << w.y() << ',' << w.z() << ',' << w.norm() << ',' << a.x() << ',' << a.y() << ','
        << a.z() << ',' << a.norm() << '\n';
  }
  if (!out.flush()) throw Error{ErrorKind::CantCreate, "cannot write " + path};
}

std::string describe(const gs::PoseSplineOptions& s) {
  std::string d = "k=" + std::to_string(s.order) + ", orientation on " +
                  (s.manifold == gs::OrientationManifold::Sphere ? "S^3 (eq. 22)" : "SO(3) (eq. 16)") +
                  ", knot velocities " + std::string(gs::to_string(s.velocity.estimator));
  if (s.velocity.estimator == gs::KnotVelocityEstimator::LocalQuadraticFit)
    d += " (w=" + std::to_string(s.velocity.fit_half_width) + ")";
  return d;
}

// Every n-th sample as knots, the others as references: errors of the spline and of
// piecewise geodesic interpolation (slerp / straight lines) at the held-out samples.
void run_holdout(const ResampleOptions& o, const PoseSequence& in) {
  const std::size_t n = static_cast<std::size_t>(*o.holdout);
  PoseSequence knots;
  for (std::size_t i = 0; i < in.size(); i += n) {
    knots.time.push_back(in.time[i]);
    knots.orientation.push_back(in.orientation[i]);
    if (in.has_position()) knots.position.push_back(in.position[i]);
  }
  if (knots.size() < 2)
    throw Error{ErrorKind::DataErr, o.input + ": --holdout " + std::to_string(n) + " leaves fewer than 2 knots"};
  const gs::PoseSpline spline(knots, o.spline);
  double rot2 = 0, rot_max = 0, pos2 = 0, pos_max = 0, geo_rot2 = 0, geo_rot_max = 0, geo_pos2 = 0, geo_pos_max = 0;
  std::size_t count = 0;
  for (std::size_t j = 0; j < in.size() && in.time[j] <= knots.time.back(); ++j) {
    if (j % n == 0) continue;
    const std::size_t i = j / n;
    const double u = (in.time[j] - knots.time[i]) / (knots.time[i + 1] - knots.time[i]);
    const gs::SplinePose p = spline.evaluate(in.time[j]);
    const double e = so3::rotation_angle(p.orientation, in.orientation[j]);
    const double g = so3::rotation_angle(so3::slerp(u, knots.orientation[i], knots.orientation[i + 1]), in.orientation[j]);
    rot2 += e * e, geo_rot2 += g * g;
    rot_max = std::max(rot_max, e), geo_rot_max = std::max(geo_rot_max, g);
    if (in.has_position()) {
      const double ep = (p.position - in.position[j]).norm();
      const double gp = ((1 - u) * knots.position[i] + u * knots.position[i + 1] - in.position[j]).norm();
      pos2 += ep * ep, geo_pos2 += gp * gp;
      pos_max = std::max(pos_max, ep), geo_pos_max = std::max(geo_pos_max, gp);
    }
    ++count;
  }
  if (count == 0) throw Error{ErrorKind::DataErr, o.input + ": no held-out samples inside the knots' range"};
  const double deg = 180.0 / std::numbers::pi;
  std::printf("holdout  every %zu-th sample as a knot: %zu knots, %zu held-out samples, %s\n", n, knots.size(), count,
              describe(o.spline).c_str());
  std::printf("spline   rotation rms %.6g deg max %.6g deg", deg * std::sqrt(rot2 / count), deg * rot_max);
  if (in.has_position()) std::printf(", position rms %.6g max %.6g", std::sqrt(pos2 / count), pos_max);
  std::printf("\ngeodesic rotation rms %.6g deg max %.6g deg", deg * std::sqrt(geo_rot2 / count), deg * geo_rot_max);
  if (in.has_position()) std::printf(", position rms %.6g max %.6g", std::sqrt(geo_pos2 / count), geo_pos_max);
  std::printf("\n");
}

int run_resample(const ResampleOptions& o) {
  const int modes = (o.rate ? 1 : 0) + (o.times_file.empty() ? 0 : 1) + (o.holdout ? 1 : 0);
  if (modes != 1) throw Error{ErrorKind::Usage, "give exactly one of --rate, --times or --holdout"};
  if (!o.holdout && o.output.empty()) throw Error{ErrorKind::Usage, "--output is required with --rate or --times"};
  try {
    gs::validate(o.spline);
  } catch (const std::invalid_argument& e) {
    throw Error{ErrorKind::Usage, e.what()};
  }
  {
    std::ifstream probe(o.input);
    if (!probe) throw Error{ErrorKind::NoInput, "cannot open " + o.input + ": " + std::strerror(errno)};
  }
  formats::ReadOptions ro;
  ro.format = o.format;
  ro.skip_missing = o.skip_missing;
  std::optional<formats::PoseFile> read;
  try {
    read.emplace(formats::read_pose_file(o.input, ro));
  } catch (const formats::PoseFileError& e) {
    throw Error{ErrorKind::DataErr, e.what()};
  }
  if (read->format() == formats::PoseFormat::Bvh)
    throw Error{ErrorKind::Usage, o.input + ": resample reads TUM or CSV files"};
  for (const std::string& w : read->warnings()) std::cerr << "posefair resample: warning: " << w << "\n";
  check_increasing(o, *read);
  const PoseSequence& in = read->poses();
  if (o.holdout) {
    run_holdout(o, in);
    return kExitOk;
  }

  std::vector<double> times = o.rate ? rate_times(in.time.front(), in.time.back(), *o.rate) : read_times(o.times_file);
  if (!o.clamp) {
    for (std::size_t i = 0; i < times.size(); ++i) {
      if (times[i] >= in.time.front() && times[i] <= in.time.back()) continue;
      std::ostringstream m;
      m.precision(17);
      m << o.times_file << ":" << data_line(o.times_file, formats::PoseFormat::Tum, i) << ": time " << times[i]
        << " is outside the data's range [" << in.time.front() << ", " << in.time.back() << "] of " << o.input
        << " (--clamp holds the end poses)";
      throw Error{ErrorKind::DataErr, m.str()};
    }
  }
  const gs::PoseSpline spline(in, o.spline);
  PoseSequence out;
  out.time = times;
  for (double t : times) {
    const gs::SplinePose p = spline.evaluate(std::clamp(t, spline.start_time(), spline.end_time()));
    out.orientation.push_back(p.orientation);
    if (in.has_position()) out.position.push_back(p.position);
  }
  so3::make_continuous(out.orientation);

  formats::PoseFormat format = read->format();
  if (o.output_format) format = *o.output_format;
  else if (auto by_name = formats::format_from_extension(o.output); by_name && *by_name != formats::PoseFormat::Bvh)
    format = *by_name;
  const formats::PoseFile document = format == formats::PoseFormat::Tum ? formats::make_tum(out) : formats::make_csv(out);
  try {
    formats::write_pose_file(o.output, document, out);
  } catch (const formats::PoseFileError& e) {
    throw Error{ErrorKind::CantCreate, e.what()};
  }
  if (!o.derivatives.empty()) write_derivatives(o.derivatives, spline, times);
  if (!o.quiet) {
    std::printf("input    %s: %zu samples, %s, %.6g s\n", o.input.c_str(), in.size(),
                in.has_position() ? "orientation + position" : "orientation only", in.time.back() - in.time.front());
    std::printf("spline   %s\n", describe(o.spline).c_str());
    std::printf("wrote    %s: %zu samples (%s)%s\n", o.output.c_str(), out.size(),
                std::string(formats::to_string(format)).c_str(), o.rate ? "" : ", at the given times");
    if (!o.derivatives.empty()) std::printf("wrote    %s: body angular velocity and acceleration\n", o.derivatives.c_str());
  }
  return kExitOk;
}

}  // namespace

void add_resample_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<ResampleOptions>();
  auto* cmd = app.add_subcommand("resample",
                                 "Resample a pose file (TUM, CSV) with geometric C^k splines (Rodrigues, Silva Leite & Jakubiak)");
  cmd->add_option("input", o->input, "pose file to read (TUM or CSV)")->required();
  cmd->add_option("-o,--output", o->output, "file to write (format by extension, else the input's)");
  const std::map<std::string, formats::PoseFormat> formats{{"tum", formats::PoseFormat::Tum},
                                                           {"csv", formats::PoseFormat::Csv}};
  cmd->add_option("--format", o->format, "input format (default: by extension)")
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case));
  cmd->add_option("--output-format", o->output_format, "output format (default: by the output's extension, else the input's)")
      ->transform(CLI::CheckedTransformer(formats, CLI::ignore_case));
  cmd->add_flag("--skip-missing", o->skip_missing, "CSV: drop rows whose quaternion is nan or empty");
  cmd->add_option("--rate", o->rate, "output rate in Hz, from the first sample's time to the last")->check(CLI::PositiveNumber);
  cmd->add_option("--times", o->times_file,
                  "output times: one per line (the first whitespace- or comma-separated field; # comments), strictly increasing");
  cmd->add_option("--holdout", o->holdout,
                  "write nothing: use every N-th sample as a knot and report the errors at the others")
      ->check(CLI::Range(2, 1000000));
  cmd->add_flag("--clamp", o->clamp, "times outside the data's range get the first or last pose instead of an error");
  cmd->add_option("-k,--order", o->spline.order, "smoothness k: the spline is C^k (1..8)")->capture_default_str();
  // Names, not the enums: CLI11 would find the enums' to_string (string_view) and fail to compile.
  cmd->add_option("--manifold", o->manifold, "orientation spline on s3 (unit quaternions, default) or so3 (rotation matrices)")
      ->check(CLI::IsMember({"s3", "so3"}, CLI::ignore_case));
  cmd->add_option("--velocity", o->velocity,
                  "knot velocity estimator: central, bessel (default) or fit (least-squares parabola)")
      ->check(CLI::IsMember({"central", "bessel", "fit"}, CLI::ignore_case));
  cmd->add_option("--fit-half-width", o->spline.velocity.fit_half_width, "fit: knots on each side (1..16)")
      ->capture_default_str();
  cmd->add_option("--derivatives", o->derivatives,
                  "also write CSV of the body-frame angular velocity (rad/s) and acceleration (rad/s^2) at the output times");
  cmd->add_flag("-q,--quiet", o->quiet, "print nothing on success");
  cmd->callback([o, &exit_code] {
    try {
      apply_names(*o);
      exit_code = run_resample(*o);
    } catch (const Error& e) {  // the message is printed after "posefair resample: "
      std::cerr << "posefair resample: " << e.what() << "\n";
      exit_code = e.exit_code();
    }
  });
}

}  // namespace posefair::tools
