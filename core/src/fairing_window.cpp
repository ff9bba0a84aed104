#include "posefair/core/fairing_window.hpp"

#include <algorithm>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "posefair/core/engine_setting.hpp"

namespace posefair {
namespace {

// Moves x onto the ball of radius eps around z (distance on S³ for rotations) if it is outside,
// and checks the result with the same distance the promise is stated in: the radius is shrunk
// step by step until rounding can no longer carry the result past eps (an absolute rounding of
// ulp(|z|) defeats any fixed relative margin for positions far from the origin, or for a tiny
// eps), and as a last resort the measurement itself is used.
bool project_rotation(const Quat& z, Quat& x, double eps) {
  if (!std::isfinite(eps) || so3::dist(z, x) <= eps) return false;
  const Vec3 v = so3::log(z.conjugate() * x);
  const double r = v.norm();
  for (double shrink : {1e-12, 1e-9, 1e-6, 1e-3}) {
    const Quat c = so3::aligned_to((z * so3::exp(v * (eps * (1.0 - shrink) / r))).normalized(), x);
    if (so3::dist(z, c) <= eps) {
      x = c;
      return true;
    }
  }
  x = so3::aligned_to(z, x);
  return true;
}

bool project_position(const Vec3& z, Vec3& p, double eps) {
  if (!std::isfinite(eps) || (p - z).norm() <= eps) return false;
  const Vec3 d = p - z;
  const double r = d.norm();
  for (double shrink : {1e-12, 1e-9, 1e-6, 1e-3}) {
    const Vec3 c = z + d * (eps * (1.0 - shrink) / r);
    if ((c - z).norm() <= eps) {
      p = c;
      return true;
    }
  }
  p = z;
  return true;
}

// In place: v (length len) -> D v (length len-1), the forward difference.
void difference(std::span<Vec3> v, int len) {
  for (int i = 0; i + 1 < len; ++i) v[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i + 1)] - v[static_cast<std::size_t>(i)];
}

// In place: v (length len) -> Dᵀ v (length len+1), the adjoint of the forward difference.
void difference_adjoint(std::span<Vec3> v, int len) {
  for (int i = len; i >= 0; --i) {
    const Vec3 prev = i > 0 ? v[static_cast<std::size_t>(i - 1)] : Vec3::Zero();
    const Vec3 here = i < len ? v[static_cast<std::size_t>(i)] : Vec3::Zero();
    v[static_cast<std::size_t>(i)] = prev - here;
  }
}

}  // namespace

void validate(const WindowConfig& c) {
  using S = EngineSetting;
  auto bad = [](EngineSetting setting, const std::string& what) { throw InvalidEngineSetting(setting, what); };
  if (c.order != 2 && c.order != 3) bad(S::Order, "order must be 2 or 3, got " + std::to_string(c.order));
  if (c.window < c.order + 1 || c.window > 4096)
    bad(S::Window, "window must hold " + std::to_string(c.order + 1) + " to 4096 samples for order " +
                       std::to_string(c.order) + ", got " + std::to_string(c.window));
  if (c.lag < 0 || c.lag >= c.window)
    bad(S::Lag, "lag must be in [0, window-1] = [0, " + std::to_string(c.window - 1) + "], got " + std::to_string(c.lag));
  if (c.iterations < 0 || c.iterations > 1000)
    bad(S::Iterations, "iterations must be in [0, 1000], got " + std::to_string(c.iterations));
  if (c.iterations == 0 && c.solver == WindowSolver::GaussNewton)
    bad(S::Iterations, "iterations must be at least 1 for the gauss-newton solver (0 would emit the warm-start extrapolation)");
  // Beyond about 1e10 the window is already an exact polynomial fit and the system only loses
  // precision (I + μDᵀD becomes numerically singular).
  if (!(c.smoothing_r >= 0.0 && c.smoothing_r <= kMaxSmoothing))
    bad(S::SmoothingR, "smoothing_r must be in [0, 1e10], got " + std::to_string(c.smoothing_r));
  if (!(c.smoothing_t >= 0.0 && c.smoothing_t <= kMaxSmoothing))
    bad(S::SmoothingT, "smoothing_t must be in [0, 1e10], got " + std::to_string(c.smoothing_t));
  if (!(c.continuity >= 0.0) || !std::isfinite(c.continuity)) bad(S::Continuity, "continuity must be finite and >= 0");
  if (!(c.lambda_r > 0.0 && c.lambda_r <= 1.0)) bad(S::LambdaR, "lambda_r must be in (0, 1]");
  if (!(c.lambda_t > 0.0 && c.lambda_t <= 1.0)) bad(S::LambdaT, "lambda_t must be in (0, 1]");
  if (!(c.epsilon_r > 0.0)) bad(S::EpsilonR, "epsilon_r must be positive");
  if (!(c.epsilon_t > 0.0)) bad(S::EpsilonT, "epsilon_t must be positive");
  if (c.continuity > 0.0 && c.window > 512) bad(S::Continuity, "continuity needs a window of at most 512 samples");
  if (c.bound == BoundPolicy::Window && c.solver == WindowSolver::Linear)
    bad(S::Bound, "the window bound policy needs an iterative solver (gauss-newton or sweeps); linear solves in closed form");
}

double smoothing_for_cutoff(double cutoff_hz, double rate_hz, int order) {
  if (!(cutoff_hz > 0.0 && rate_hz > 0.0 && cutoff_hz < rate_hz / 2.0))
    throw std::invalid_argument("the cutoff must be positive and below half the sample rate");
  const double s = 2.0 * std::sin(std::numbers::pi * cutoff_hz / rate_hz);
  return std::pow(s, -2.0 * order);
}

FairingWindow::FairingWindow(const WindowConfig& config) : config_(config), gate_(config.gate) {
  validate(config);
  const auto w = static_cast<std::size_t>(config.window);
  samples_.resize(w);
  z_.resize(w);
  x_.resize(w);
  zeta_.resize(w);
  est_.resize(w);
  window_clamped_.assign(w, 0);
  c_.resize(w);
  y_.resize(w);
  zp_.resize(w);
  xp_.resize(w);
  yp_.resize(w);
  e_.resize(w);
  u_.resize(w);
  w_.resize(w + 1);
  rhs_.resize(w);
  target_.resize(w);
  diag_.resize(w);
  if (config.solver != WindowSolver::DampedSweeps) {
    // One factorisation per fill level n; samples with index < n-1-L have been emitted.
    factors_r_.resize(w + 1);
    factors_t_.resize(w + 1);
    for (int n = 1; n <= config.window; ++n) {
      for (int i = 0; i < n; ++i) diag_[static_cast<std::size_t>(i)] = 1.0 + (i < n - 1 - config.lag ? config.continuity : 0.0);
      factors_r_[static_cast<std::size_t>(n)] = make_smoothing_system(n, config.order, config.smoothing_r, std::span(diag_).first(static_cast<std::size_t>(n)));
      factors_t_[static_cast<std::size_t>(n)] = make_smoothing_system(n, config.order, config.smoothing_t, std::span(diag_).first(static_cast<std::size_t>(n)));
    }
    if (config.solver == WindowSolver::Linear || config.continuity > 0.0) precompute_linear_rows();
    if (config.continuity > 0.0) check_continuity_stability();
  }
}

// With κ > 0 every emitted orientation feeds back into later ones: in a full window the
// emitted correction obeys c_k = Σ_j a_j c_{k−j} + (terms in the data), a linear recursion that
// diverges for some (μ, κ, W, L). Its characteristic roots are the eigenvalues of the companion
// matrix of a; a configuration whose spectral radius is not below 1 is refused here rather than
// left to blow up on a live stream.
void FairingWindow::check_continuity_stability() const {
  const int w = config_.window, lag = config_.lag;
  const int taps = w - 1 - lag;  // emitted samples in a full window
  if (taps <= 0) return;
  const auto& g = row_c_[static_cast<std::size_t>(w)];
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(taps, taps);
  // c at window index taps-1 is the newest emitted (one step back), index 0 the oldest.
  for (int j = 1; j <= taps; ++j) companion(0, j - 1) = g[static_cast<std::size_t>(taps - j)];
  for (int j = 1; j < taps; ++j) companion(j, j - 1) = 1.0;
  const double radius = companion.eigenvalues().cwiseAbs().maxCoeff();
  if (!(radius < 1.0 - 1e-9))
    throw InvalidEngineSetting(EngineSetting::Continuity, "continuity " + std::to_string(config_.continuity) + " with smoothing " +
        std::to_string(config_.smoothing_r) + ", window " + std::to_string(w) + " and lag " +
        std::to_string(lag) + " makes the output recursion unstable (spectral radius " +
        std::to_string(radius) + "); lower the continuity or the smoothing");
}

void FairingWindow::precompute_linear_rows() {
  // Row k of A⁻¹ is r = A⁻¹ e_k (A is symmetric). The emitted estimate is
  //   e_k = rᵀ(κ E c − μ (D^m)ᵀ D^{m−1} ζ) = Σ κ r_i c_i (emitted i) + hᵀζ,  h = −μ (D^{m−1})ᵀ D^m r,
  //   p_k = rᵀ(z_p + κ E y_p).
  const int w = config_.window, m = config_.order, lag = config_.lag;
  row_zeta_.resize(static_cast<std::size_t>(w + 1));
  row_c_.resize(static_cast<std::size_t>(w + 1));
  row_p_.resize(static_cast<std::size_t>(w + 1));
  std::vector<Vec3> unit(static_cast<std::size_t>(w));
  for (int n = 1; n <= w; ++n) {
    const int k = n - 1 - lag;
    if (k < 0) continue;
    for (const bool rotation : {true, false}) {
      std::fill(unit.begin(), unit.end(), Vec3::Zero());
      unit[static_cast<std::size_t>(k)] = Vec3::Ones();
      (rotation ? factors_r_ : factors_t_)[static_cast<std::size_t>(n)].solve(std::span(unit).first(static_cast<std::size_t>(n)));
      std::vector<double> r(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) r[static_cast<std::size_t>(i)] = unit[static_cast<std::size_t>(i)].x();
      auto& c = rotation ? row_c_[static_cast<std::size_t>(n)] : row_p_[static_cast<std::size_t>(n)];
      c.assign(static_cast<std::size_t>(n), 0.0);
      for (int i = 0; i < n; ++i) {
        const bool emitted = i < n - 1 - lag;
        c[static_cast<std::size_t>(i)] = rotation ? (emitted ? config_.continuity * r[static_cast<std::size_t>(i)] : 0.0)
                                                  : r[static_cast<std::size_t>(i)];
      }
      if (!rotation) continue;
      auto& h = row_zeta_[static_cast<std::size_t>(n)];
      h.assign(static_cast<std::size_t>(std::max(0, n - 1)), 0.0);
      if (n <= m || config_.smoothing_r == 0.0) continue;
      // h = −μ (D^{m−1})ᵀ D^m r, with the same difference/adjoint passes the solver uses.
      for (int i = 0; i < n; ++i) unit[static_cast<std::size_t>(i)] = Vec3::Constant(r[static_cast<std::size_t>(i)]);
      int len = n;
      for (int p = 0; p < m; ++p) difference(unit, len--);
      for (int p = 1; p < m; ++p) difference_adjoint(unit, len++);
      for (int j = 0; j < n - 1; ++j) h[static_cast<std::size_t>(j)] = -config_.smoothing_r * unit[static_cast<std::size_t>(j)].x();
    }
  }
}

void FairingWindow::linear_emission_estimate(int k) {
  const auto n = static_cast<std::size_t>(n_);
  const auto& h = row_zeta_[n];
  const auto& g = row_c_[n];
  Vec3 e = Vec3::Zero();
  for (std::size_t j = 0; j + 1 < n; ++j) e += h[j] * zeta_[j];
  // Only emitted samples carry a c (the others' entries are stale or unset, and g is 0 there).
  if (config_.continuity > 0.0)
    for (std::size_t i = 0; static_cast<int>(i) < n_ - 1 - config_.lag; ++i) e += g[i] * c_[i];
  est_[static_cast<std::size_t>(k)] = e;
  if (positions_) {
    const auto& rp = row_p_[n];
    Vec3 p = Vec3::Zero();
    const int emitted = n_ - 1 - config_.lag;
    for (std::size_t i = 0; i < n; ++i) {
      Vec3 v = zp_[i];
      if (config_.continuity > 0.0 && static_cast<int>(i) < emitted) v += config_.continuity * yp_[i];
      p += rp[i] * v;
    }
    xp_[static_cast<std::size_t>(k)] = p;
  }
}

std::size_t FairingWindow::memory_bytes() const {
  std::size_t bytes = sizeof(*this);
  bytes += samples_.capacity() * sizeof(Sample);
  bytes += (z_.capacity() + x_.capacity() + y_.capacity() + target_.capacity()) * sizeof(Quat);
  bytes += (zeta_.capacity() + est_.capacity() + c_.capacity()) * sizeof(Vec3);
  bytes += (zp_.capacity() + xp_.capacity() + yp_.capacity() + e_.capacity() + u_.capacity() + w_.capacity() +
            rhs_.capacity()) * sizeof(Vec3);
  bytes += diag_.capacity() * sizeof(double) + window_clamped_.capacity();
  for (const auto* rows : {&row_zeta_, &row_c_, &row_p_}) {
    bytes += rows->capacity() * sizeof(std::vector<double>);
    for (const auto& r : *rows) bytes += r.capacity() * sizeof(double);
  }
  for (const auto* set : {&factors_r_, &factors_t_}) {
    bytes += set->capacity() * sizeof(BandedCholesky);
    for (const BandedCholesky& f : *set) bytes += static_cast<std::size_t>(f.size() * (f.bandwidth() + 1)) * sizeof(double);
  }
  return bytes;
}

int FairingWindow::first_unemitted() const { return std::max(0, n_ - config_.lag); }

FairedPose FairingWindow::emit(int index) {
  const auto k = static_cast<std::size_t>(index);
  Quat q = config_.solver == WindowSolver::Linear ? Quat((z_[k] * so3::exp(est_[k])).normalized()) : x_[k];
  bool clamped = project_rotation(z_[k], q, config_.epsilon_r);
  // The stream stays hemisphere-continuous across window restarts too.
  if (have_emitted_) q = so3::aligned_to(q, last_emitted_);
  last_emitted_ = q;
  have_emitted_ = true;
  // The linear solver's continuity term needs the emitted correction log(z⁻¹ y).
  if (config_.solver == WindowSolver::Linear && config_.continuity > 0.0) c_[k] = so3::log(z_[k].conjugate() * q);
  Vec3 p = xp_[k];
  if (positions_) clamped = project_position(zp_[k], p, config_.epsilon_t) || clamped;
  // With the window policy the projection may already have happened inside the solve.
  clamped = clamped || window_clamped_[k];
  if (clamped) ++counters_.clamped;
  y_[k] = q;
  yp_[k] = p;
  ++counters_.emitted;
  const Sample& s = samples_[k];
  FairedPose out;
  out.stream_id = s.stream_id;
  out.sequence = s.sequence;
  out.time = s.time;
  out.orientation = q;
  out.position = positions_ ? p : Vec3::Zero();
  out.measured = s.orientation;
  out.measured_position = s.position;
  out.flags = s.flags | (clamped ? kClamped : 0u);
  return out;
}

int FairingWindow::emit_pending(std::span<FairedPose> out) {
  int count = 0;
  // The linear solver keeps no estimates between samples: solve the whole window once here.
  if (config_.solver == WindowSolver::Linear && first_unemitted() < n_) solve();
  for (int i = first_unemitted(); i < n_; ++i) out[static_cast<std::size_t>(count++)] = emit(i);
  n_ = 0;
  return count;
}

int FairingWindow::flush(std::span<FairedPose> out) { return emit_pending(out); }

int FairingWindow::push(const Sample& sample, std::span<FairedPose> out) {
  Sample s = sample;
  const GateVerdict verdict = gate_.check(s);
  if (verdict != GateVerdict::Accept && verdict != GateVerdict::AcceptAfterGap) return 0;
  int count = 0;
  // A gap, or a change between streams with and without positions, starts a new window.
  if (n_ > 0 && (verdict == GateVerdict::AcceptAfterGap || s.has_position() != positions_)) {
    count = emit_pending(out);
    ++counters_.restarts;
  }
  append(s);
  const int k = n_ - 1 - config_.lag;
  if (config_.solver == WindowSolver::Linear) {
    // Only the emitted sample's estimate is needed: one precomputed dot product.
    if (k >= 0) linear_emission_estimate(k);
  } else {
    solve();
  }
  if (k >= 0) out[static_cast<std::size_t>(count++)] = emit(k);
  return count;
}

void FairingWindow::append(const Sample& s) {
  if (n_ == 0) positions_ = s.has_position();
  if (n_ == config_.window) {
    // Slide: drop the oldest (emitted long ago). W moves of a few dozen bytes each.
    std::move(samples_.begin() + 1, samples_.end(), samples_.begin());
    std::move(z_.begin() + 1, z_.end(), z_.begin());
    if (config_.solver == WindowSolver::Linear) {
      std::move(zeta_.begin() + 1, zeta_.end(), zeta_.begin());
      std::move(c_.begin() + 1, c_.end(), c_.begin());
    } else {
      std::move(x_.begin() + 1, x_.end(), x_.begin());
      std::move(y_.begin() + 1, y_.end(), y_.begin());
      std::move(window_clamped_.begin() + 1, window_clamped_.end(), window_clamped_.begin());
    }
    if (positions_) {
      std::move(zp_.begin() + 1, zp_.end(), zp_.begin());
      std::move(xp_.begin() + 1, xp_.end(), xp_.begin());
      std::move(yp_.begin() + 1, yp_.end(), yp_.begin());
    }
    --n_;
  }
  const auto k = static_cast<std::size_t>(n_);
  samples_[k] = s;
  window_clamped_[k] = 0;
  Quat z = s.orientation;
  if (n_ == 0) {
    if (z.w() < 0.0) z.coeffs() = -z.coeffs();
  } else {
    z = so3::aligned_to(z, z_[k - 1]);
  }
  z_[k] = z;
  if (config_.solver == WindowSolver::Linear) {
    if (n_ >= 1) zeta_[k - 1] = so3::log(z_[k - 1].conjugate() * z);
    if (positions_) zp_[k] = s.position;
    ++n_;
    return;
  }
  // Warm start: the previous window's estimates stay. The paper's sweeps have no data term, so
  // the new sample must start at its measurement; Gauss–Newton starts it at the
  // constant-velocity prediction of the estimates before it (its data term pulls it from there).
  if (n_ >= 2 && config_.solver == WindowSolver::GaussNewton) {
    const Quat& a = x_[k - 2];
    const Quat& b = x_[k - 1];
    x_[k] = so3::aligned_to((b * (a.conjugate() * b)).normalized(), z);
  } else {
    x_[k] = z;
  }
  if (positions_) {
    zp_[k] = s.position;
    xp_[k] = n_ >= 2 && config_.solver == WindowSolver::GaussNewton ? Vec3(2.0 * xp_[k - 1] - xp_[k - 2]) : s.position;
  }
  ++n_;
}

void FairingWindow::solve() {
  if (config_.solver == WindowSolver::Linear) {
    linear_rotation(factors_r_[static_cast<std::size_t>(n_)]);
    if (positions_) solve_positions(factors_t_[static_cast<std::size_t>(n_)]);
  } else if (config_.solver == WindowSolver::GaussNewton) {
    for (int it = 0; it < config_.iterations; ++it) {
      gauss_newton_rotation(factors_r_[static_cast<std::size_t>(n_)]);
      if (config_.bound == BoundPolicy::Window) bound_window();
    }
    if (positions_) {
      solve_positions(factors_t_[static_cast<std::size_t>(n_)]);
      if (config_.bound == BoundPolicy::Window) bound_window();
    }
  } else {
    sweeps();
  }
}

// rhs -= μ (D^m)ᵀ D^{m-1} w1, where w1 (in w_, n-1 entries) is W¹ of the linearisation point:
// the gradient of μ‖W^m x‖² with W^m x = D^{m-1} W¹x and W¹ linear in the correction.
void FairingWindow::smoothness_gradient(std::span<const Vec3> w1) {
  const int n = n_, m = config_.order;
  if (w1.data() != w_.data()) std::copy(w1.begin(), w1.begin() + (n - 1), w_.begin());
  int len = n - 1;
  for (int p = 1; p < m; ++p) difference(w_, len--);
  for (int p = 0; p < m; ++p) difference_adjoint(w_, len++);
  for (int i = 0; i < n; ++i) rhs_[static_cast<std::size_t>(i)] -= config_.smoothing_r * w_[static_cast<std::size_t>(i)];
}

void FairingWindow::linear_rotation(const BandedCholesky& a) {
  const int n = n_;
  const int emitted = n - 1 - config_.lag;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    rhs_[k] = config_.continuity > 0.0 && i < emitted ? Vec3(config_.continuity * c_[k]) : Vec3::Zero();
  }
  if (n > config_.order && config_.smoothing_r > 0.0) smoothness_gradient(std::span<const Vec3>(zeta_).first(static_cast<std::size_t>(n - 1)));
  a.solve(std::span(rhs_).first(static_cast<std::size_t>(n)));
  std::copy(rhs_.begin(), rhs_.begin() + n, est_.begin());
}

void FairingWindow::gauss_newton_rotation(const BandedCholesky& a) {
  const int n = n_;
  const int m = config_.order;
  const double mu = config_.smoothing_r;
  const double kappa = config_.continuity;
  const int emitted = n - 1 - config_.lag;  // indices below this were emitted
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    Vec3 g = so3::log(z_[k].conjugate() * x_[k]);  // data residual
    if (kappa > 0.0 && i < emitted) g += kappa * so3::log(y_[k].conjugate() * x_[k]);
    rhs_[k] = -g;
  }
  if (n > m && mu > 0.0) {
    for (int j = 0; j + 1 < n; ++j) w_[static_cast<std::size_t>(j)] = so3::log(x_[static_cast<std::size_t>(j)].conjugate() * x_[static_cast<std::size_t>(j + 1)]);
    smoothness_gradient(w_);
  }
  a.solve(std::span(rhs_).first(static_cast<std::size_t>(n)));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    x_[k] = (x_[k] * so3::exp(rhs_[k])).normalized();
  }
}

void FairingWindow::solve_positions(const BandedCholesky& a) {
  // Linear: (I + κE + μ (D^m)ᵀD^m) p = z + κ E y, solved exactly.
  const int emitted = n_ - 1 - config_.lag;
  for (int i = 0; i < n_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    rhs_[k] = zp_[k];
    if (config_.continuity > 0.0 && i < emitted) rhs_[k] += config_.continuity * yp_[k];
  }
  a.solve(std::span(rhs_).first(static_cast<std::size_t>(n_)));
  for (int i = 0; i < n_; ++i) xp_[static_cast<std::size_t>(i)] = rhs_[static_cast<std::size_t>(i)];
}

void FairingWindow::sweeps() {
  const int m = config_.order;
  if (n_ < min_samples_for_order(m)) return;
  const auto n = static_cast<std::size_t>(n_);
  for (int it = 0; it < config_.iterations; ++it) {
    damped_rotation_sweep(m, config_.variant, config_.lambda_r, std::span(x_).first(n), std::span(u_).first(n - 1),
                          std::span(target_).first(n));
    if (positions_) damped_position_sweep(m, config_.lambda_t, std::span(xp_).first(n), std::span(e_).first(n));
    if (config_.bound == BoundPolicy::Window) bound_window();
  }
}

void FairingWindow::bound_window() {
  for (int i = 0; i < n_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    bool moved = project_rotation(z_[k], x_[k], config_.epsilon_r);
    if (positions_) moved = project_position(zp_[k], xp_[k], config_.epsilon_t) || moved;
    if (moved) window_clamped_[k] = 1;
  }
}

}  // namespace posefair
