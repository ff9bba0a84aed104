#include "quality_datasets.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <ostream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "benchmark_data.hpp"
#include "posefair/core/quality_metrics.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {
namespace {

// Smooth truth plus bounded noise (Section 6 style), 10 s (quick: 3 s).
QualityDataset synthetic(double rate, double noise, bool quick) {
  SyntheticMotionSpec spec;
  spec.sample_rate_hz = rate;
  spec.samples = static_cast<std::size_t>((quick ? 3.0 : 10.0) * rate);
  spec.cycles = quick ? 1.5 : 5.0;  // about 0.5 Hz motion
  spec.rotation_noise = noise;
  spec.with_position = false;
  spec.seed = 11;
  const auto m = make_synthetic_motion(spec);
  QualityDataset d;
  char name[64];
  std::snprintf(name, sizeof name, "synthetic-%gHz-noise%g", rate, noise);
  d.name = name;
  d.kind = "synthetic";
  d.input = m.noisy;
  d.truth = m.truth.orientation;
  d.rate_hz = rate;
  d.use.assign(d.input.size(), 1);
  for (std::size_t i = 0; i < d.use.size() && static_cast<double>(i) < 0.5 * rate; ++i) d.use[i] = 0;  // warm-up
  return d;
}

// A SLAM estimate scored against motion capture, interpolated to the estimate's times and
// brought into the estimate's frames (world and body alignment fitted on the raw estimate).
QualityDataset tum(const std::filesystem::path& est_path, const std::filesystem::path& gt_path, const std::string& name) {
  formats::ReadOptions ro;
  ro.format = formats::PoseFormat::Tum;
  const PoseSequence est = formats::read_pose_file(est_path, ro).poses();
  const PoseSequence gt = formats::read_pose_file(gt_path, ro).poses();
  QualityDataset d;
  d.name = name;
  d.kind = "tum";
  for (std::size_t i = 0; i < est.size(); ++i) {
    const double t = est.time[i];
    if (t < gt.time.front() || t > gt.time.back()) continue;
    if (!d.input.time.empty() && t <= d.input.time.back()) continue;
    d.input.time.push_back(t);
    d.input.orientation.push_back(est.orientation[i]);
    d.truth.push_back(orientation_at(gt, t));
  }
  const FrameAlignment a = align_frames(d.input.orientation, d.truth, true);
  for (Quat& q : d.truth) q = (a.world.conjugate() * q * a.body.conjugate()).normalized();
  d.rate_hz = median_sample_rate(d.input.time);
  d.use.assign(d.input.size(), 1);
  return d;
}

// BROAD: optical orientation (with dropouts left out) against the gyroscope, scored in the
// movement phases.
QualityDataset broad(const std::filesystem::path& path, const std::string& name) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path.string() + ": cannot open");
  std::string line;
  std::getline(f, line);
  if (line.rfind("t_s,gt_qw,gt_qx,gt_qy,gt_qz,gt_px_m,gt_py_m,gt_pz_m,gyr_x_rads,gyr_y_rads,gyr_z_rads", 0) != 0)
    throw std::runtime_error(path.string() + ":1: not a BROAD CSV header");
  const auto header_fields = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',') + 1);
  const std::size_t movement_col = header_fields - 1;
  QualityDataset d;
  d.name = name;
  d.kind = "broad";
  std::vector<double> v;
  std::size_t lineno = 1;
  while (std::getline(f, line)) {
    ++lineno;
    v.clear();
    std::size_t start = 0;
    while (start <= line.size()) {
      const std::size_t end = std::min(line.find(',', start), line.size());
      double x = std::nan("");
      const std::string_view field(line.data() + start, end - start);
      if (field != "nan") {
        const auto [p, ec] = std::from_chars(field.data(), field.data() + field.size(), x);
        if (ec != std::errc() || p != field.data() + field.size())
          throw std::runtime_error(path.string() + ":" + std::to_string(lineno) + ": bad number '" + std::string(field) + "'");
      }
      v.push_back(x);
      start = end + 1;
    }
    if (v.size() != header_fields) throw std::runtime_error(path.string() + ":" + std::to_string(lineno) + ": wrong field count");
    if (std::isnan(v[1])) continue;  // optical dropout
    d.input.time.push_back(v[0]);
    d.input.orientation.push_back(Quat(v[1], v[2], v[3], v[4]).normalized());
    d.gyro.emplace_back(v[8], v[9], v[10]);
    d.use.push_back(v[movement_col] > 0.5 ? 1 : 0);
  }
  d.rate_hz = median_sample_rate(d.input.time);
  // A rate interval is scored only if both ends are consecutive samples (no dropout between).
  for (std::size_t i = 0; i + 1 < d.input.size(); ++i)
    if (d.input.time[i + 1] - d.input.time[i] > 1.5 / d.rate_hz) d.use[i] = 0;
  return d;
}

// A BVH joint (frame 0, the T-pose, left out) with bounded random rotations added.
QualityDataset bvh(const std::filesystem::path& path, const std::string& joint, double noise, const std::string& name) {
  formats::ReadOptions ro;
  ro.bvh_joint = joint;
  PoseSequence clean = formats::read_pose_file(path, ro).poses();
  QualityDataset d;
  d.name = name;
  d.kind = "bvh";
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 1; i < clean.size(); ++i) {
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    d.input.time.push_back(clean.time[i]);
    d.truth.push_back(clean.orientation[i]);
    d.input.orientation.push_back((clean.orientation[i] * so3::exp(dir * noise * u(rng))).normalized());
  }
  d.rate_hz = median_sample_rate(d.input.time);
  d.use.assign(d.input.size(), 1);
  return d;
}

}  // namespace

std::vector<QualityDataset> load_quality_datasets(const std::filesystem::path& dir, bool quick, std::ostream& notes) {
  std::vector<QualityDataset> sets;
  for (double rate : {100.0, 1000.0})
    for (double noise : {0.01, 0.05}) sets.push_back(synthetic(rate, noise, quick));
  if (quick) return sets;
  // The recorded sets are read in full from dir. One whose files are missing is skipped with a
  // line saying where it comes from; none of them there at all is an error.
  const std::initializer_list<std::string_view> all_files = {
      "tum/freiburg1_xyz-rgbdslam.txt", "tum/freiburg1_xyz-groundtruth.txt", "tum/fr2_desk_ORB.txt",
      "tum/fr2_desk_groundtruth.txt", "broad/07_undisturbed_fast_rotation_B.csv",
      "broad/02_undisturbed_slow_rotation_B.csv", "bvh/01_01.bvh", "bvh/Boxing_Toes.bvh"};
  if (std::none_of(all_files.begin(), all_files.end(), [&](std::string_view f) { return std::filesystem::exists(dir / f); })) {
    std::string m = "no recorded data set found in " + dir.string() + ":";
    for (std::string_view f : all_files) m += "\n  " + missing_file_line(dir, f);
    throw std::runtime_error(m + "\n" + where_benchmark_data_is_looked_for());
  }
  const auto present = [&](const std::string& name, std::initializer_list<std::string_view> files) {
    for (std::string_view f : files)
      if (!std::filesystem::exists(dir / f)) {
        notes << "posefair bench quality: skipping " << name << ": " << missing_file_line(dir, f) << "\n";
        return false;
      }
    return true;
  };
  if (present("tum-fr1xyz-rgbdslam", {"tum/freiburg1_xyz-rgbdslam.txt", "tum/freiburg1_xyz-groundtruth.txt"}))
    sets.push_back(tum(dir / "tum/freiburg1_xyz-rgbdslam.txt", dir / "tum/freiburg1_xyz-groundtruth.txt", "tum-fr1xyz-rgbdslam"));
  if (present("tum-fr2desk-orb", {"tum/fr2_desk_ORB.txt", "tum/fr2_desk_groundtruth.txt"}))
    sets.push_back(tum(dir / "tum/fr2_desk_ORB.txt", dir / "tum/fr2_desk_groundtruth.txt", "tum-fr2desk-orb"));
  if (present("broad-07-fast-rotation", {"broad/07_undisturbed_fast_rotation_B.csv"}))
    sets.push_back(broad(dir / "broad/07_undisturbed_fast_rotation_B.csv", "broad-07-fast-rotation"));
  if (present("broad-02-slow-rotation", {"broad/02_undisturbed_slow_rotation_B.csv"}))
    sets.push_back(broad(dir / "broad/02_undisturbed_slow_rotation_B.csv", "broad-02-slow-rotation"));
  if (present("bvh-01_01-LeftArm-noise0.02", {"bvh/01_01.bvh"}))
    sets.push_back(bvh(dir / "bvh/01_01.bvh", "LeftArm", 0.02, "bvh-01_01-LeftArm-noise0.02"));
  if (present("bvh-01_01-RightUpLeg-noise0.02", {"bvh/01_01.bvh"}))
    sets.push_back(bvh(dir / "bvh/01_01.bvh", "RightUpLeg", 0.02, "bvh-01_01-RightUpLeg-noise0.02"));
  if (present("bvh-boxing-RightShoulder-noise0.02", {"bvh/Boxing_Toes.bvh"}))
    sets.push_back(bvh(dir / "bvh/Boxing_Toes.bvh", "RightShoulder", 0.02, "bvh-boxing-RightShoulder-noise0.02"));
  return sets;
}

}  // namespace posefair::tools
