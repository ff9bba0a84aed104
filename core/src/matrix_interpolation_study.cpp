#include "posefair/core/eigen_matrix_functions.hpp"
#include "posefair/core/matrix_interpolation_study.hpp"

#include "posefair/core/linear_combination.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>

namespace posefair {
namespace {

using Eigen::Vector3d;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool has_principal_log(const Mat4& a) { return check_principal_logarithm(a).index() == 0; }

double relative_error(const Mat4& x, const Mat4& ref) { return norm_inf(x - ref) / std::max(norm_inf(ref), 1e-300); }

Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Vector3d v;
  do v = Vector3d(g(rng), g(rng), g(rng));
  while (v.norm() < 1e-6);
  return v.normalized();
}

// A camera somewhere around the unit sphere at the origin, looking near its centre.
CameraParams random_camera(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto in = [&](double a, double b) { return a + (b - a) * u01(rng); };
  CameraParams c;
  c.from = random_unit(rng) * in(3.0, 6.0);
  c.at = Vector3d(in(-0.3, 0.3), in(-0.3, 0.3), in(-0.3, 0.3));
  Vector3d up;
  do up = Vector3d::UnitY() + 0.3 * random_unit(rng);
  while (up.normalized().cross((c.at - c.from).normalized()).norm() < 0.2);
  c.up = up;
  c.lens.fov_y = in(30.0, 60.0) * std::numbers::pi / 180.0;
  c.lens.aspect = in(0.8, 1.25);
  c.lens.skew = in(-0.2, 0.2);
  c.lens.cop_u = in(-0.3, 0.3);
  c.lens.cop_v = in(-0.3, 0.3);
  c.lens.near = 0.1;
  c.lens.far = 100.0;
  return c;
}

std::vector<Vector3d> sphere_mesh(int rings, int segments) {
  std::vector<Vector3d> v{Vector3d::UnitZ(), -Vector3d::UnitZ()};
  for (int i = 1; i < rings; ++i) {
    const double th = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double ph = 2.0 * std::numbers::pi * j / segments;
      v.emplace_back(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
    }
  }
  return v;
}

double median(std::vector<double> x) {
  if (x.empty()) return kNaN;
  std::sort(x.begin(), x.end());
  const std::size_t n = x.size();
  return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

}  // namespace

Mat4 random_test_transform(std::mt19937_64& rng, double min_angle, double max_angle) {
  std::uniform_real_distribution<double> angle(min_angle, max_angle), log_scale(-2.0, 2.0), shift(0.1, 100.0);
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(angle(rng), Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(angle(rng), Vector3d::UnitY()) *
                             Eigen::AngleAxisd(angle(rng), Vector3d::UnitX()))
                                .toRotationMatrix();
  const Vector3d s(std::pow(10.0, log_scale(rng)), std::pow(10.0, log_scale(rng)), std::pow(10.0, log_scale(rng)));
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = r * s.asDiagonal();
  m.topRightCorner<3, 1>() = Vector3d(shift(rng), shift(rng), shift(rng));
  return m;
}

std::vector<SqrtStudyRow> sqrt_iteration_study(int matrices, int iterations, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<SqrtStudyRow> rows;
  SqrtOptions o;
  o.epsilon = 0.0;  // never stop early: record every iteration
  o.max_iterations = iterations;
  for (int m = 0; m < matrices; ++m) {
    const Mat4 a = random_test_transform(rng);
    const bool principal = has_principal_log(a);
    SqrtTrace trace;
    (void)denman_beavers_sqrt(a, o, &trace);
    for (std::size_t i = 0; i < trace.residuals.size(); ++i)
      rows.push_back({m, static_cast<int>(i), trace.residuals[i], principal});
  }
  return rows;
}

std::vector<LogStudyRow> log_square_root_study(int matrices, int max_roots, double eps3, bool relative_eps3,
                                               std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<LogStudyRow> rows;
  for (int m = 0; m < matrices; ++m) {
    const Mat4 a = random_test_transform(rng);
    if (!has_principal_log(a)) continue;  // no real logarithm to study (counted by the caller)
    const Mat4 ref = eigen_matrix_log(a);
    Mat4 previous = Mat4::Zero();
    bool previous_ok = false;
    for (int n = 0; n <= max_roots; ++n) {
      LogOptions o;
      o.fixed_square_roots = n;
      o.max_series_terms = 60;
      o.sqrt.epsilon = eps3;
      o.sqrt.relative = relative_eps3;
      o.sqrt.max_iterations = 30;
      LogTrace t;
      MatrixResult r = matrix_log(a, o, &t);
      LogStudyRow row{m, n, kNaN, -1, kNaN, kNaN};
      // The distance reached, also when the series then failed.
      Mat4 x = a;
      bool roots_ok = true;
      for (int i = 0; i < n && roots_ok; ++i) {
        MatrixResult s = denman_beavers_sqrt(x, o.sqrt);
        roots_ok = s.ok();
        if (roots_ok) x = s.value();
      }
      if (roots_ok) row.distance_to_identity = norm_inf(x - Mat4::Identity());
      if (r) {
        row.series_terms = t.series_terms;
        row.error = relative_error(r.value(), ref);
        if (previous_ok) row.change = norm_inf(r.value() - previous);
        previous = r.value();
      }
      previous_ok = r.ok();
      rows.push_back(row);
    }
  }
  return rows;
}

LargeRotationStudy large_rotation_study(int matrices, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  LargeRotationStudy s;
  s.matrices = matrices;
  for (int m = 0; m < matrices; ++m) {
    // The composite rotation matters (Rz(pi) Ry(pi) Rx(pi) = I): keep those of pi/2 or more.
    Mat4 a;
    do a = random_test_transform(rng);
    while (rotational_component(a) < std::numbers::pi / 2.0);
    const bool negative = !has_principal_log(a);
    const bool sqrt_ok = denman_beavers_sqrt(a).ok();
    s.negative_eigenvalue += negative;
    s.sqrt_failed += !sqrt_ok;
    s.sqrt_failed_without_negative += !sqrt_ok && !negative;
    MatrixResult l = matrix_log(a);
    if (!l && l.error().code == MatrixErrorCode::NoConvergence) ++s.log_root_cap;
    if (l) {
      ++s.log_ok;
      s.worst_log_error = std::max(s.worst_log_error, relative_error(l.value(), eigen_matrix_log(a)));
    }
  }
  return s;
}

PathStudy path_length_study(int pairs, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<Vector3d> mesh = sphere_mesh(8, 16);
  PathStudy s;
  std::vector<double> par, mat;
  const int steps = 10;
  while (static_cast<int>(s.pairs.size()) < pairs) {
    const CameraParams a = random_camera(rng), b = random_camera(rng);
    const CameraKey ka = camera_key(a), kb = camera_key(b);
    const double rot = rotational_component(kb.origin * ka.origin.inverse());
    Result<PreparedLerp> lerp = PreparedLerp::make(ka.matrix, kb.matrix, ka.origin);
    if (!lerp) {
      ++s.rejected_unsafe;
      continue;
    }
    // Screen paths of every vertex under both methods.
    std::vector<std::vector<Eigen::Vector2d>> path_p(mesh.size()), path_m(mesh.size());
    std::vector<bool> usable(mesh.size(), true);
    for (int i = 0; i <= steps; ++i) {
      const double t = static_cast<double>(i) / steps;
      const Mat4 cp = camera_parameter_lerp_matrix(a, b, t);
      MatrixResult m = lerp.value().at(t);
      const Mat4 cm = perspective_a((1.0 - t) * ka.k + t * kb.k) * m.value();
      for (std::size_t v = 0; v < mesh.size(); ++v) {
        const Eigen::Vector4d h(mesh[v].x(), mesh[v].y(), mesh[v].z(), 1.0);
        const Eigen::Vector4d qp = cp * h, qm = cm * h;
        if (qp.w() <= 0.0 || qm.w() <= 0.0) usable[v] = false;
        path_p[v].push_back(qp.head<2>() / qp.w());
        path_m[v].push_back(qm.head<2>() / qm.w());
      }
    }
    auto length = [](const std::vector<Eigen::Vector2d>& p) {
      double l = 0.0;
      for (std::size_t i = 1; i < p.size(); ++i) l += (p[i] - p[i - 1]).norm();
      return l;
    };
    double sum_p = 0.0, sum_m = 0.0;
    int used = 0;
    for (std::size_t v = 0; v < mesh.size(); ++v) {
      const double l0 = (path_p[v].back() - path_p[v].front()).norm();
      if (!usable[v] || l0 < 0.01) {
        ++s.vertices_skipped;
        continue;
      }
      // Both methods start and end at the keyframes, so l0 is the same for both.
      sum_p += 100.0 * (length(path_p[v]) - l0) / l0;
      sum_m += 100.0 * (length(path_m[v]) - l0) / l0;
      ++used;
    }
    if (used == 0) continue;
    PathPairRow row{static_cast<int>(s.pairs.size()), rot * 180.0 / std::numbers::pi, sum_p / used, sum_m / used,
                    used};
    s.pairs.push_back(row);
    par.push_back(row.excess_parameter);
    mat.push_back(row.excess_matrix);
  }
  double mp = 0.0, mm = 0.0;
  for (std::size_t i = 0; i < par.size(); ++i) {
    mp += par[i];
    mm += mat[i];
  }
  s.mean_parameter = par.empty() ? kNaN : mp / par.size();
  s.mean_matrix = mat.empty() ? kNaN : mm / mat.size();
  s.median_parameter = median(par);
  s.median_matrix = median(mat);
  return s;
}

}  // namespace posefair
