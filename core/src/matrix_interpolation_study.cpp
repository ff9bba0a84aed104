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

Mat4 random_test_transform(std::mt19937_64& rng, double min_angle, double max_angle, ScaleDraw scales) {
  std::uniform_real_distribution<double> angle(min_angle, max_angle), log_scale(-2.0, 2.0), scale(1e-2, 1e2),
      shift(0.1, 100.0);
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(angle(rng), Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(angle(rng), Vector3d::UnitY()) *
                             Eigen::AngleAxisd(angle(rng), Vector3d::UnitX()))
                                .toRotationMatrix();
  // (Kept as one expression per draw: the order in which the three draws are made is the
  // compiler's, and the documented numbers were made with it.)
  const Vector3d s = scales == ScaleDraw::LogUniform
                         ? Vector3d(std::pow(10.0, log_scale(rng)), std::pow(10.0, log_scale(rng)),
                                    std::pow(10.0, log_scale(rng)))
                         : Vector3d(scale(rng), scale(rng), scale(rng));
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

LargeRotationStudy large_rotation_study(int matrices, std::uint64_t seed, ScaleDraw scales) {
  std::mt19937_64 rng(seed);
  LargeRotationStudy s;
  s.matrices = matrices;
  for (int m = 0; m < matrices; ++m) {
    // The composite rotation matters (Rz(pi) Ry(pi) Rx(pi) = I): keep those of pi/2 or more.
    Mat4 a;
    do a = random_test_transform(rng, 0.0, std::numbers::pi, scales);
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

PathStudy path_length_study(int pairs, std::uint64_t seed, KeyPairDraw draw) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const std::vector<Vector3d> mesh = sphere_mesh(8, 16);
  PathStudy s;
  const int steps = 10;
  while (static_cast<int>(s.pairs.size()) < pairs) {
    const CameraParams a = random_camera(rng);
    CameraParams b = random_camera(rng);  // its lens (and, for Independent, everything)
    double drawn = kNaN;
    if (draw == KeyPairDraw::UniformAngle) {
      // Turn a's whole view by the angle about a random axis: b's view rotation is then a's
      // times that turn; its distance to the looked-at point is b's own.
      drawn = 0.5 * std::numbers::pi * u01(rng);
      const Eigen::Matrix3d g = Eigen::AngleAxisd(drawn, random_unit(rng)).toRotationMatrix();
      b.at = g * a.at;
      b.up = g * a.up;
      b.from = b.at + g * (a.from - a.at).normalized() * (b.from - b.at).norm();
    }
    const CameraKey ka = camera_key(a), kb = camera_key(b);
    const double rot = rotational_component(kb.origin * ka.origin.inverse());
    Result<PreparedLerp> lerp = PreparedLerp::make(ka.matrix, kb.matrix, ka.origin);
    if (!lerp) {
      ++s.rejected_unsafe;
      continue;
    }
    // Paths of every vertex under both methods, in camera space and on the screen.
    const std::size_t nv = mesh.size();
    std::vector<std::vector<Vector3d>> cam_p(nv), cam_m(nv);
    std::vector<std::vector<Eigen::Vector2d>> scr_p(nv), scr_m(nv);
    std::vector<bool> in_front(nv, true);
    for (int i = 0; i <= steps; ++i) {
      const double t = static_cast<double>(i) / steps;
      const Mat4 ap = camera_parameter_lerp_affine(a, b, t), cp = camera_parameter_lerp_matrix(a, b, t);
      const Mat4 am = lerp.value().at(t).value(), cm = perspective_a((1.0 - t) * ka.k + t * kb.k) * am;
      for (std::size_t v = 0; v < nv; ++v) {
        const Eigen::Vector4d h(mesh[v].x(), mesh[v].y(), mesh[v].z(), 1.0);
        cam_p[v].push_back((ap * h).head<3>());
        cam_m[v].push_back((am * h).head<3>());
        const Eigen::Vector4d qp = cp * h, qm = cm * h;
        if (qp.w() <= 0.0 || qm.w() <= 0.0) in_front[v] = false;
        scr_p[v].push_back(qp.head<2>() / qp.w());
        scr_m[v].push_back(qm.head<2>() / qm.w());
      }
    }
    auto length = [](const auto& p) {
      double l = 0.0;
      for (std::size_t i = 1; i < p.size(); ++i) l += (p[i] - p[i - 1]).norm();
      return l;
    };
    // The mesh's radius in camera space at key a: the scale for "did not move".
    double radius = 0.0;
    const Vector3d centre = (ka.matrix * Eigen::Vector4d(0, 0, 0, 1)).head<3>();
    for (std::size_t v = 0; v < nv; ++v) radius = std::max(radius, (cam_m[v].front() - centre).norm());
    // Mean excess over the usable vertices; both methods start and end at the keys, so l0 is shared.
    auto excess = [&](const auto& path_p, const auto& path_m, double min_l0, bool screen, int& skipped, int& used,
                      double& ex_p, double& ex_m) {
      double sum_p = 0.0, sum_m = 0.0;
      used = 0;
      for (std::size_t v = 0; v < nv; ++v) {
        const double l0 = (path_p[v].back() - path_p[v].front()).norm();
        if ((screen && !in_front[v]) || l0 < min_l0) {
          ++skipped;
          continue;
        }
        sum_p += 100.0 * (length(path_p[v]) - l0) / l0;
        sum_m += 100.0 * (length(path_m[v]) - l0) / l0;
        ++used;
      }
      ex_p = used ? sum_p / used : kNaN;
      ex_m = used ? sum_m / used : kNaN;
    };
    PathPairRow row{static_cast<int>(s.pairs.size()), drawn * 180.0 / std::numbers::pi, rot * 180.0 / std::numbers::pi,
                    kNaN, kNaN, kNaN, kNaN, 0, 0};
    int cam_skipped = 0, scr_skipped = 0;
    excess(cam_p, cam_m, 1e-3 * radius, false, cam_skipped, row.camera_vertices, row.camera_parameter, row.camera_matrix);
    excess(scr_p, scr_m, 0.01, true, scr_skipped, row.screen_vertices, row.screen_parameter, row.screen_matrix);
    if (row.camera_vertices == 0 || row.screen_vertices == 0) continue;
    s.camera_skipped += cam_skipped;
    s.screen_skipped += scr_skipped;
    s.pairs.push_back(row);
  }
  auto summarise = [&](double PathPairRow::*par, double PathPairRow::*mat) {
    PathMeans m;
    std::vector<double> p, q;
    for (const PathPairRow& r : s.pairs) {
      p.push_back(r.*par);
      q.push_back(r.*mat);
      m.matrix_lower += r.*mat < r.*par;
    }
    for (std::size_t i = 0; i < p.size(); ++i) {
      m.mean_parameter += p[i] / static_cast<double>(p.size());
      m.mean_matrix += q[i] / static_cast<double>(q.size());
    }
    m.median_parameter = median(p);
    m.median_matrix = median(q);
    return m;
  };
  s.camera = summarise(&PathPairRow::camera_parameter, &PathPairRow::camera_matrix);
  s.screen = summarise(&PathPairRow::screen_parameter, &PathPairRow::screen_matrix);
  return s;
}

}  // namespace posefair
