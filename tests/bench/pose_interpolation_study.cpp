// Which interpolation of full poses is closer to the truth between samples? Recorded poses
// with position are thinned to every m-th sample; the samples left out are the truth at their
// times, and each interpolation is scored there:
//   matrix-lerp   Alexa's lerp of the 4x4 transform between the two neighbours (the daemon's
//                 pose_interpolation = "matrix-lerp", rigid_pose_lerp.hpp)
//   slerp+line    slerp and a straight line for the position, between the same neighbours
//   spline k=1/2  the daemon's "spline": the geometric C^k spline (Bessel velocities, S^3) on
//                 rotation and position separately
// Intervals across a dropout (a step over 1.5 m median intervals) are not scored. Prints RMS
// rotation error (degrees) and RMS position error (mm for TUM and BROAD, 1e-3 file units for
// BVH) per data set and m.
//   build/tests/bench/pose_interpolation_study [data dir, default $POSEFAIR_DATA or ../shared/data]
// A data set whose file is missing is skipped with a line; none there at all is an error (exit 66).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "benchmark_data.hpp"
#include "posefair/core/error.hpp"
#include "posefair/core/pose_spline.hpp"
#include "posefair/core/rigid_pose_lerp.hpp"
#include "posefair/formats/pose_file.hpp"

namespace {

using namespace posefair;

struct Data {
  std::string name;
  PoseSequence poses;
};

double median_step(const std::vector<double>& t) {
  std::vector<double> d;
  for (std::size_t i = 1; i < t.size(); ++i) d.push_back(t[i] - t[i - 1]);
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

// Strictly increasing times (fr2_desk has one repeated timestamp), hemisphere-continuous.
PoseSequence cleaned(const PoseSequence& p, std::size_t first = 0) {
  PoseSequence c;
  for (std::size_t i = first; i < p.size(); ++i) {
    if (!c.time.empty() && !(p.time[i] > c.time.back())) continue;
    c.time.push_back(p.time[i]);
    c.orientation.push_back(p.orientation[i]);
    c.position.push_back(p.position[i]);
  }
  so3::make_continuous(c.orientation);
  return c;
}

struct Score {
  double rot_sq = 0.0, pos_sq = 0.0;
  std::size_t n = 0;
  void add(const Quat& q, const Vec3& p, const Quat& tq, const Vec3& tp) {
    const double r = so3::rotation_angle(q, tq) * 180.0 / std::numbers::pi;
    rot_sq += r * r;
    pos_sq += 1e6 * (p - tp).squaredNorm();
    ++n;
  }
  double rot() const { return std::sqrt(rot_sq / static_cast<double>(n)); }
  double pos() const { return std::sqrt(pos_sq / static_cast<double>(n)); }
};

void study(const Data& d, std::size_t m) {
  const PoseSequence& all = d.poses;
  PoseSequence knots;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < all.size(); i += m) {
    knots.time.push_back(all.time[i]);
    knots.orientation.push_back(all.orientation[i]);
    knots.position.push_back(all.position[i]);
    index.push_back(i);
  }
  geometric_splines::PoseSplineOptions o1, o2;
  o1.order = 1;
  o2.order = 2;
  const geometric_splines::PoseSpline spline1(knots, o1), spline2(knots, o2);
  const double limit = 1.5 * static_cast<double>(m) * median_step(all.time);
  RigidPoseLerp lerp;
  Score s_lerp, s_line, s_k1, s_k2;
  std::size_t intervals = 0;
  for (std::size_t k = 0; k + 1 < index.size(); ++k) {
    const std::size_t a = index[k], b = index[k + 1];
    const double span = all.time[b] - all.time[a];
    if (span > limit) continue;
    ++intervals;
    lerp.prepare(all.orientation[a], all.position[a], all.orientation[b], all.position[b]);
    for (std::size_t i = a + 1; i < b; ++i) {
      const double t = all.time[i], f = (t - all.time[a]) / span;
      const Quat& tq = all.orientation[i];
      const Vec3& tp = all.position[i];
      Quat q;
      Vec3 p;
      lerp.at(f, q, p);
      s_lerp.add(q, p, tq, tp);
      s_line.add(so3::slerp(f, all.orientation[a], all.orientation[b]), all.position[a] + f * (all.position[b] - all.position[a]),
                 tq, tp);
      const auto p1 = spline1.evaluate(t), p2 = spline2.evaluate(t);
      s_k1.add(p1.orientation, p1.position, tq, tp);
      s_k2.add(p2.orientation, p2.position, tq, tp);
    }
  }
  const double rate = 1.0 / (static_cast<double>(m) * median_step(all.time));
  std::printf("| %s | %zu (%.0f Hz) | %zu | %.4f / %.3f | %.4f / %.3f | %.4f / %.3f | %.4f / %.3f | %llu |\n", d.name.c_str(), m,
              rate, s_lerp.n, s_lerp.rot(), s_lerp.pos(), s_line.rot(), s_line.pos(), s_k1.rot(), s_k1.pos(), s_k2.rot(),
              s_k2.pos(), static_cast<unsigned long long>(lerp.fallbacks()));
  (void)intervals;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? std::filesystem::path(argv[1]) : posefair::tools::benchmark_data_dir();
  std::vector<Data> sets;
  std::size_t missing = 0;
  const auto present = [&](const std::string& relative) {
    if (std::filesystem::exists(dir / relative)) return true;
    std::fprintf(stderr, "pose_interpolation_study: skipping %s: %s\n", relative.c_str(),
                 posefair::tools::missing_file_line(dir, relative).c_str());
    ++missing;
    return false;
  };
  try {
    formats::ReadOptions tum;
    tum.format = formats::PoseFormat::Tum;
    for (const char* f : {"freiburg1_xyz-groundtruth.txt", "fr2_desk_groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "fr2_desk_ORB.txt"})
      if (present(std::string("tum/") + f))
        sets.push_back({std::string("tum/") + f, cleaned(formats::read_pose_file(dir / "tum" / f, tum).poses())});
    formats::ReadOptions broad;
    broad.csv_prefix = "gt_";
    broad.skip_missing = true;
    for (const char* f : {"16_undisturbed_fast_translation_B.csv", "21_undisturbed_fast_combined.csv"})
      if (present(std::string("broad/") + f))
        sets.push_back({std::string("broad/") + f, cleaned(formats::read_pose_file(dir / "broad" / f, broad).poses())});
    formats::ReadOptions bvh;
    bvh.bvh_joint = "Hips";
    if (present("bvh/01_01.bvh"))
      sets.push_back({"bvh/01_01.bvh Hips", cleaned(formats::read_pose_file(dir / "bvh" / "01_01.bvh", bvh).poses(), 1)});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pose_interpolation_study: %s\n", e.what());
    return 1;
  }
  if (sets.empty()) {
    std::fprintf(stderr, "pose_interpolation_study: no recorded data set found in %s (%zu files missing).\n%s\n",
                 dir.string().c_str(), missing, posefair::tools::where_benchmark_data_is_looked_for().c_str());
    return posefair::exit_code(posefair::ErrorKind::NoInput);  // as posefair bench quality
  }
  std::printf("RMS error at the held-out samples: rotation (deg) / position (mm; BVH: 1e-3 file units)\n\n");
  std::printf("| data | keep every m (rate) | poses scored | matrix-lerp | slerp+line | spline k=1 | spline k=2 | lerp fallbacks |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Data& d : sets)
    for (std::size_t m : {2u, 4u, 8u}) study(d, m);
  return 0;
}
