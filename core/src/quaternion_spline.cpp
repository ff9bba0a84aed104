#include "posefair/core/quaternion_spline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

#include <nlopt.hpp>

#include "posefair/core/covariant_acceleration.hpp"

namespace posefair {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Where each node's free quantities live in the optimiser's vector (−1: fixed).
struct ParameterLayout {
  std::vector<int> velocity, position;
  int size = 0;
};

ParameterLayout layout_of(const QuaternionSpline& s) {
  ParameterLayout l;
  const std::size_t n = s.curve.nodes().size();
  l.velocity.assign(n, -1);
  l.position.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (s.velocity_free(i)) l.velocity[i] = std::exchange(l.size, l.size + 4);
    if (s.position_free(i)) l.position[i] = std::exchange(l.size, l.size + 4);
  }
  return l;
}

void pack(const HermiteCurve4& c, const ParameterLayout& l, std::vector<double>& x) {
  x.resize(static_cast<std::size_t>(l.size));
  for (std::size_t i = 0; i < c.nodes().size(); ++i) {
    if (l.velocity[i] >= 0) Vec4::Map(&x[static_cast<std::size_t>(l.velocity[i])]) = c.nodes()[i].velocity;
    if (l.position[i] >= 0) Vec4::Map(&x[static_cast<std::size_t>(l.position[i])]) = c.nodes()[i].position;
  }
}

void unpack(const double* x, const ParameterLayout& l, HermiteCurve4& c) {
  for (std::size_t i = 0; i < c.nodes().size(); ++i) {
    if (l.velocity[i] >= 0) c.nodes()[i].velocity = Vec4::Map(x + l.velocity[i]);
    if (l.position[i] >= 0) c.nodes()[i].position = Vec4::Map(x + l.position[i]);
  }
}

struct Problem {
  HermiteCurve4* curve;
  const ParameterLayout* layout;
  const SplineObjective* objective;
  ObjectiveGradient gradient;
  int evaluations = 0;
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> best_x;
};

double evaluate(const std::vector<double>& x, std::vector<double>& grad, void* data) {
  auto& p = *static_cast<Problem*>(data);
  ++p.evaluations;
  unpack(x.data(), *p.layout, *p.curve);
  double f;
  if (grad.empty()) {
    f = p.objective->value(*p.curve);
  } else {
    f = p.objective->value_and_gradient(*p.curve, p.gradient);
    for (std::size_t i = 0; i < p.curve->nodes().size(); ++i) {
      if (p.layout->velocity[i] >= 0) Vec4::Map(&grad[static_cast<std::size_t>(p.layout->velocity[i])]) = p.gradient.d_velocity[i];
      if (p.layout->position[i] >= 0) Vec4::Map(&grad[static_cast<std::size_t>(p.layout->position[i])]) = p.gradient.d_position[i];
    }
  }
  // NLopt may end on an exception (e.g. roundoff limited); keep the best point it visited.
  if (f < p.best) {
    p.best = f;
    p.best_x = x;
  }
  return f;
}

std::string_view describe(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS: return "success";
    case nlopt::STOPVAL_REACHED: return "stopval reached";
    case nlopt::FTOL_REACHED: return "ftol reached";
    case nlopt::XTOL_REACHED: return "xtol reached";
    case nlopt::MAXEVAL_REACHED: return "maxeval reached";
    case nlopt::MAXTIME_REACHED: return "maxtime reached";
    default: return "failure";
  }
}

}  // namespace

Vec4 quaternion_velocity(const Vec3& omega, const Quat& q) {
  const Quat w(0.0, omega.x(), omega.y(), omega.z());
  return 0.5 * to_vec4(w * q);
}

std::string_view to_string(SplineOptimizer m) { return m == SplineOptimizer::Lbfgs ? "lbfgs" : "slsqp"; }

bool QuaternionSpline::velocity_free(std::size_t node) const {
  if (node == 0 && start_velocity_fixed) return false;
  if (node + 1 == curve.nodes().size() && end_velocity_fixed) return false;
  return true;
}

int QuaternionSpline::variable_frames() const {
  return static_cast<int>(std::count(is_variable_frame.begin(), is_variable_frame.end(), char{1}));
}

int QuaternionSpline::free_parameters() const { return layout_of(*this).size; }

QuaternionSpline initial_spline(const SplineKeyframes& keys) {
  const std::size_t n = keys.time.size();
  if (keys.orientation.size() != n) throw std::invalid_argument("keyframes: as many times as orientations needed");
  if (n < 2) throw std::invalid_argument("keyframes: need at least two, got " + std::to_string(n));
  std::vector<Quat> q(keys.orientation);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(keys.time[i])) throw std::invalid_argument("keyframes: non-finite time at key " + std::to_string(i));
    if (i > 0 && !(keys.time[i] > keys.time[i - 1]))
      throw std::invalid_argument("keyframes: times must increase strictly (key " + std::to_string(i) + ")");
    const double norm = q[i].norm();
    if (!std::isfinite(norm) || norm == 0.0)
      throw std::invalid_argument("keyframes: zero or non-finite quaternion at key " + std::to_string(i));
    q[i].coeffs() /= norm;
  }
  // Neighbouring keys in one hemisphere, so differences and cubics follow the shorter arcs.
  so3::make_continuous(q);

  std::vector<HermiteNode> nodes(n);
  for (std::size_t i = 0; i < n; ++i) {
    nodes[i].time = keys.time[i];
    nodes[i].position = to_vec4(q[i]);
  }
  // Step 2: central differences inside, one-sided differences at free ends (footnote 2).
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t lo = i == 0 ? 0 : i - 1, hi = i + 1 == n ? n - 1 : i + 1;
    nodes[i].velocity = (nodes[hi].position - nodes[lo].position) / (nodes[hi].time - nodes[lo].time);
  }
  QuaternionSpline s;
  if (keys.omega_start) {
    nodes.front().velocity = quaternion_velocity(*keys.omega_start, q.front());
    s.start_velocity_fixed = true;
  }
  if (keys.omega_end) {
    nodes.back().velocity = quaternion_velocity(*keys.omega_end, q.back());
    s.end_velocity_fixed = true;
  }
  s.curve = HermiteCurve4(std::move(nodes));
  s.is_variable_frame.assign(n, 0);
  return s;
}

OptimizeReport optimize_spline(QuaternionSpline& spline, const SplineObjective& objective,
                               const OptimizerSettings& settings) {
  const auto t0 = Clock::now();
  const ParameterLayout layout = layout_of(spline);
  OptimizeReport report;
  if (layout.size == 0) {
    report.objective = objective.value(spline.curve);
    report.status = "nothing to optimise";
    return report;
  }
  std::vector<double> x;
  pack(spline.curve, layout, x);
  Problem p{&spline.curve, &layout, &objective, {}, 0, std::numeric_limits<double>::infinity(), {}};
  nlopt::opt opt(settings.method == SplineOptimizer::Lbfgs ? nlopt::LD_LBFGS : nlopt::LD_SLSQP,
                 static_cast<unsigned>(layout.size));
  opt.set_min_objective(evaluate, &p);
  if (settings.method == SplineOptimizer::Lbfgs) opt.set_vector_storage(10);
  opt.set_ftol_rel(settings.relative_tolerance);
  opt.set_maxeval(settings.max_evaluations);
  double f = 0.0;
  try {
    report.status = describe(opt.optimize(x, f));
  } catch (const nlopt::roundoff_limited&) {
    report.status = "roundoff limited";  // converged as far as doubles allow
  } catch (const std::runtime_error& e) {
    report.status = std::string("failure: ") + e.what();
  }
  if (!p.best_x.empty()) unpack(p.best_x.data(), layout, spline.curve);
  report.objective = p.best_x.empty() ? objective.value(spline.curve) : p.best;
  report.evaluations = p.evaluations;
  report.seconds = seconds_since(t0);
  return report;
}

std::vector<RefinementSegment> refinement_segments(std::span<const double> key_times, int per_interval) {
  if (per_interval < 1) throw std::invalid_argument("refinement_segments: need at least one segment per interval");
  std::vector<RefinementSegment> out;
  for (std::size_t i = 0; i + 1 < key_times.size(); ++i) {
    const double h = (key_times[i + 1] - key_times[i]) / per_interval;
    for (int k = 0; k < per_interval; ++k) {
      RefinementSegment s;
      s.start = key_times[i] + k * h;
      s.end = k + 1 == per_interval ? key_times[i + 1] : key_times[i] + (k + 1) * h;
      s.starts_at_keyframe = k == 0;
      out.push_back(s);
    }
  }
  return out;
}

std::vector<double> segment_deviation(const HermiteCurve4& curve, double alpha,
                                      std::span<const RefinementSegment> segments, int points) {
  const QuadratureRule rule = gauss_legendre_rule(points);
  std::vector<double> dev;
  dev.reserve(segments.size());
  for (const RefinementSegment& s : segments) {
    double mean = 0.0;  // the weights sum to one, so this is (1/Δt) ∫ |EL| dt
    for (std::size_t k = 0; k < rule.node.size(); ++k)
      mean += rule.weight[k] * euler_lagrange_vector(curve.jet(s.start + rule.node[k] * (s.end - s.start)), alpha).norm();
    dev.push_back(mean);
  }
  return dev;
}

int add_variable_frames(QuaternionSpline& spline, std::span<const RefinementSegment> segments,
                        std::span<const double> deviation, int count) {
  std::vector<std::size_t> order(segments.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return deviation[a] > deviation[b]; });
  int added = 0;
  for (std::size_t i : order) {
    if (added >= count) break;
    const RefinementSegment& s = segments[i];
    if (s.starts_at_keyframe) continue;
    const auto& nodes = spline.curve.nodes();
    const std::size_t piece = spline.curve.piece_at(s.start);
    // Segment starts are computed the same way every round, so an existing frame compares equal;
    // the relative slack only guards against a node that is not a segment start.
    const double slack = 1e-9 * (nodes[piece + 1].time - nodes[piece].time);
    if (std::abs(nodes[piece].time - s.start) <= slack || std::abs(nodes[piece + 1].time - s.start) <= slack) continue;
    const std::size_t at = spline.curve.split_at(s.start);
    spline.is_variable_frame.insert(spline.is_variable_frame.begin() + static_cast<std::ptrdiff_t>(at), char{1});
    ++added;
  }
  return added;
}

void split_every_piece(QuaternionSpline& spline) {
  std::vector<double> mids;
  for (std::size_t i = 0; i < spline.curve.pieces(); ++i)
    mids.push_back(0.5 * (spline.curve.nodes()[i].time + spline.curve.nodes()[i + 1].time));
  for (double t : mids) {
    const std::size_t at = spline.curve.split_at(t);
    spline.is_variable_frame.insert(spline.is_variable_frame.begin() + static_cast<std::ptrdiff_t>(at), char{1});
  }
}

double max_norm_deviation(const HermiteCurve4& curve, int samples_per_piece) {
  double worst = 0.0;
  for (std::size_t i = 0; i < curve.pieces(); ++i)
    for (int k = 0; k <= samples_per_piece; ++k)
      worst = std::max(worst, std::abs(curve.jet_on_piece(i, static_cast<double>(k) / samples_per_piece).q.norm() - 1.0));
  return worst;
}

QuaternionSplineResult build_quaternion_spline(const SplineKeyframes& keys, const QuaternionSplineOptions& o) {
  if (!(o.alpha >= 0.0) || o.variable_frames < 0 || o.frames_per_round < 1 || o.target_improvement < 0.0 ||
      o.quadrature_points < 1 || o.deviation_points < 1)
    throw std::invalid_argument("quaternion spline: invalid options");
  const SplineObjective objective(o.alpha, o.quadrature_points);
  double elapsed = 0.0;  // algorithm time only

  QuaternionSplineResult r;
  auto t = Clock::now();
  r.spline = initial_spline(keys);
  r.segments = refinement_segments(keys.time, o.segments_per_interval);
  elapsed += seconds_since(t);
  r.initial = r.spline;

  auto record = [&](bool optimized, int evaluations) {
    SplineStage s;
    s.variable_frames = r.spline.variable_frames();
    s.optimized = optimized;
    s.objective = objective.value(r.spline.curve);
    s.covariant = objective.covariant_part(r.spline.curve);
    s.seconds = elapsed;
    s.evaluations = evaluations;
    s.max_norm_deviation = max_norm_deviation(r.spline.curve);
    const std::vector<double> dev = segment_deviation(r.spline.curve, o.alpha, r.segments, o.deviation_points);
    s.max_el_deviation = *std::max_element(dev.begin(), dev.end());
    s.mean_el_deviation = std::accumulate(dev.begin(), dev.end(), 0.0) / static_cast<double>(dev.size());
    r.stages.push_back(s);
  };
  record(false, 0);
  if (!o.optimize) return r;

  OptimizeReport rep = optimize_spline(r.spline, objective, o.optimizer);
  elapsed += rep.seconds;
  record(true, rep.evaluations);

  while (r.spline.variable_frames() < o.variable_frames) {
    t = Clock::now();
    const std::vector<double> dev = segment_deviation(r.spline.curve, o.alpha, r.segments, o.deviation_points);
    const int want = std::min(o.frames_per_round, o.variable_frames - r.spline.variable_frames());
    const int added = add_variable_frames(r.spline, r.segments, dev, want);
    elapsed += seconds_since(t);
    if (added == 0) break;  // every segment start already holds a frame
    const double before = r.stages.back().objective;
    rep = optimize_spline(r.spline, objective, o.optimizer);
    elapsed += rep.seconds;
    record(true, rep.evaluations);
    if (o.target_improvement > 0.0 && before - rep.objective < o.target_improvement * std::abs(rep.objective)) break;
  }
  return r;
}

}  // namespace posefair
