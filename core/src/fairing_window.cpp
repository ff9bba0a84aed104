#include "posefair/core/fairing_window.hpp"

#include <algorithm>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "posefair/core/difference_operators.hpp"
#include "posefair/core/engine_setting.hpp"
#include "posefair/core/weighted_vector_sum.hpp"

namespace posefair {
namespace {

// How far a measured rate may be left (as a ratio, either way) before the window follows.
constexpr double kRateChange = 1.5;

// A step between the last two poses whose square is this many times their noise's is motion,
// carried on whole to a repeat (carried_share); within it, by its Wiener weight.
constexpr double kClearStep = 9.0;

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

enum class SmoothingSource { Given, Cutoff, Adaptive };

SmoothingSource smoothing_source(const WindowConfig& c, bool rotation) {
  if (rotation ? c.smoothing_r.has_value() : c.smoothing_t.has_value()) return SmoothingSource::Given;
  if (c.cutoff_hz) return SmoothingSource::Cutoff;
  return SmoothingSource::Adaptive;
}

// The fixed μ of a channel at this rate (a cutoff needs the rate; one at or above half the
// rate, possible only with a measured rate, is held just below it).
double fixed_smoothing(const WindowConfig& c, bool rotation, double rate) {
  const std::optional<double>& given = rotation ? c.smoothing_r : c.smoothing_t;
  if (given) return *given;
  return smoothing_for_cutoff(std::min(*c.cutoff_hz, 0.45 * rate), rate, c.order);
}

// Whether a channel's smoothing is known without the stream's rate.
bool resolvable(const WindowConfig& c, bool rotation) {
  const SmoothingSource s = smoothing_source(c, rotation);
  return s == SmoothingSource::Given || (s == SmoothingSource::Cutoff && c.rate_hz > 0.0);
}

}  // namespace

void validate(const WindowConfig& c) {
  using S = EngineSetting;
  auto bad = [](EngineSetting setting, const std::string& what) { throw InvalidEngineSetting(setting, what); };
  if (c.order != 2 && c.order != 3) bad(S::Order, "order must be 2 or 3, got " + std::to_string(c.order));
  if (c.window != 0 && (c.window < c.order + 1 || c.window > 4096))
    bad(S::Window, "window must hold " + std::to_string(c.order + 1) + " to 4096 samples for order " +
                       std::to_string(c.order) + ", got " + std::to_string(c.window));
  if (!(c.window_s > 0.0 && c.window_s <= 60.0)) bad(S::Window, "window_s must be in (0, 60] seconds, got " + std::to_string(c.window_s));
  if (c.max_window < kMinWindowSamples || c.max_window > 4096)
    bad(S::Window, "max_window must be in [" + std::to_string(kMinWindowSamples) + ", 4096], got " + std::to_string(c.max_window));
  if (c.window > 0 && (c.lag < 0 || c.lag >= c.window))
    bad(S::Lag, "lag must be in [0, window-1] = [0, " + std::to_string(c.window - 1) + "], got " + std::to_string(c.lag));
  if (c.window == 0 && (c.lag < 0 || c.lag > c.max_window - 2))
    bad(S::Lag, "lag must be in [0, max_window-2] = [0, " + std::to_string(c.max_window - 2) + "], got " + std::to_string(c.lag));
  if (!(c.horizon_s >= 0.0 && c.horizon_s <= 1.0)) bad(S::Horizon, "horizon must be in [0, 1] seconds, got " + std::to_string(c.horizon_s));
  if (c.horizon_s > 0.0) {
    if (c.lag != 0) bad(S::Horizon, "a horizon (prediction) needs lag 0");
    if (c.solver != WindowSolver::Linear) bad(S::Horizon, "a horizon (prediction) needs the linear solver");
    if (c.continuity > 0.0) bad(S::Horizon, "a horizon (prediction) cannot be combined with continuity");
    if (std::isfinite(c.epsilon_r) || std::isfinite(c.epsilon_t))
      bad(S::Horizon, "a horizon (prediction) cannot be combined with an epsilon bound: a predicted pose has no measurement to be bounded by");
  }
  if (c.iterations < 0 || c.iterations > 1000)
    bad(S::Iterations, "iterations must be in [0, 1000], got " + std::to_string(c.iterations));
  if (c.iterations == 0 && c.solver == WindowSolver::GaussNewton)
    bad(S::Iterations, "iterations must be at least 1 for the gauss-newton solver (0 would emit the warm-start extrapolation)");
  // Beyond about 1e10 the window is already an exact polynomial fit and the system only loses
  // precision (I + μDᵀD becomes numerically singular).
  if (c.smoothing_r && !(*c.smoothing_r >= 0.0 && *c.smoothing_r <= kMaxSmoothing))
    bad(S::SmoothingR, "smoothing_r must be in [0, 1e10], got " + std::to_string(*c.smoothing_r));
  if (c.smoothing_t && !(*c.smoothing_t >= 0.0 && *c.smoothing_t <= kMaxSmoothing))
    bad(S::SmoothingT, "smoothing_t must be in [0, 1e10], got " + std::to_string(*c.smoothing_t));
  if (!(c.rate_hz >= 0.0) || !std::isfinite(c.rate_hz)) bad(S::Rate, "rate_hz must be finite and >= 0 (0: measured)");
  if (c.cutoff_hz) {
    if (!(*c.cutoff_hz > 0.0) || !std::isfinite(*c.cutoff_hz)) bad(S::Cutoff, "cutoff_hz must be positive");
    if (c.rate_hz > 0.0 && !(*c.cutoff_hz < c.rate_hz / 2.0)) bad(S::Cutoff, "cutoff_hz must be below half of rate_hz");
  }
  const AdaptationSettings& a = c.adaptation;
  for (double t : {a.noise_time_s, a.motion_time_s, a.motion_span_s})
    if (!(t > 0.0 && t <= kMaxAdaptationTime)) bad(S::Adaptation, "the adaptation's time constants must be in (0, 600] seconds");
  if (!(a.rest_threshold >= 0.0 && a.rest_threshold <= kMaxRestThreshold))
    bad(S::Adaptation, "the rest threshold must be in [0, 100]");
  if (!(a.rest_memory_s >= 0.0 && a.rest_memory_s <= kMaxAdaptationTime))
    bad(S::Adaptation, "the rest memory must be in [0, 600] seconds (0: off)");
  if (!(a.motion_margin > 0.0 && a.motion_margin <= kMaxMotionMargin))
    bad(S::Adaptation, "the adaptation's motion margin must be in (0, 100]");
  if (c.outlier_threshold && !(*c.outlier_threshold >= 0.0 && *c.outlier_threshold <= kMaxOutlierThreshold))
    bad(S::OutlierThreshold, "outlier_threshold must be in [0, 1000] (0: off), got " + std::to_string(*c.outlier_threshold));
  if (!(c.continuity >= 0.0) || !std::isfinite(c.continuity)) bad(S::Continuity, "continuity must be finite and >= 0");
  if (c.continuity > 0.0) {
    if (c.window == 0) bad(S::Continuity, "continuity needs a window in samples (its stability is checked for that window)");
    if (c.window > 512) bad(S::Continuity, "continuity needs a window of at most 512 samples");
    if (!resolvable(c, true) || !resolvable(c, false))
      bad(S::Continuity, "continuity needs fixed smoothing (smoothing, or cutoff_hz with rate_hz): its stability is checked for it");
  }
  if (c.solver != WindowSolver::Linear) {
    if (c.window == 0) bad(S::Window, "the iterative solvers need window in samples; window_s is the linear solver's");
    if (c.solver == WindowSolver::GaussNewton && !resolvable(c, true))
      bad(S::SmoothingR, "the gauss-newton solver needs smoothing (or cutoff_hz with rate_hz): adaptation is the linear solver's");
  }
  if (!(c.lambda_r > 0.0 && c.lambda_r <= 1.0)) bad(S::LambdaR, "lambda_r must be in (0, 1]");
  if (!(c.lambda_t > 0.0 && c.lambda_t <= 1.0)) bad(S::LambdaT, "lambda_t must be in (0, 1]");
  if (!(c.epsilon_r > 0.0)) bad(S::EpsilonR, "epsilon_r must be positive");
  if (!(c.epsilon_t > 0.0)) bad(S::EpsilonT, "epsilon_t must be positive");
  if (c.bound == BoundPolicy::Window && c.solver == WindowSolver::Linear)
    bad(S::Bound, "the window bound policy needs an iterative solver (gauss-newton or sweeps); linear solves in closed form");
}

double smoothing_for_cutoff(double cutoff_hz, double rate_hz, int order) {
  if (!(cutoff_hz > 0.0 && rate_hz > 0.0 && cutoff_hz < rate_hz / 2.0))
    throw std::invalid_argument("the cutoff must be positive and below half the sample rate");
  const double s = 2.0 * std::sin(std::numbers::pi * cutoff_hz / rate_hz);
  return std::pow(s, -2.0 * order);
}

double cutoff_for_smoothing(double mu, double rate_hz, int order) {
  if (!(rate_hz > 0.0)) return 0.0;
  if (!(mu > 0.0)) return rate_hz / 2.0;  // no smoothing: everything up to Nyquist passes
  const double s = std::pow(mu, -1.0 / (2.0 * order));
  return rate_hz * std::asin(std::min(1.0, 0.5 * s)) / std::numbers::pi;
}

double outlier_threshold(const WindowConfig& config) {
  if (config.outlier_threshold) return *config.outlier_threshold;
  return config.lag > 0 || emits_held_as_measured(config) ? kDefaultOutlierThreshold : 0.0;
}

// Only the linear solver can emit a held sample as measured and then put the prediction in its
// place (push, put_held): it keeps no estimate between samples.
bool emits_held_as_measured(const WindowConfig& config) {
  return config.lag == 0 && config.solver == WindowSolver::Linear;
}

FairingWindow::Channel::Channel(int capacity, int order)
    : fixed(make_emission_row(capacity)), blend{std::vector<double>(static_cast<std::size_t>(std::max(1, capacity)), 0.0)}, estimator(capacity, order) {}

FairingWindow::FairingWindow(const WindowConfig& config)
    : config_(config),
      gate_(config.gate),
      capacity_((validate(config), config.window > 0 ? config.window : config.max_window)),
      w_(capacity_),
      target_spec_{config.order, config.lag, 0.0, config.continuity},
      builder_(capacity_, config.order),
      fill_row_(make_emission_row(capacity_)),
      fill_newest_row_(make_emission_row(capacity_)),
      rot_(capacity_, config.order),
      pos_(capacity_, config.order),
      rot_guard_(outlier_threshold(config), 0.5),  // log gives half the rotation angle
      pos_guard_(outlier_threshold(config), 1.0),
      gyro_(config.gyro),
      aided_estimator_(capacity_, config.order) {
  const auto w = static_cast<std::size_t>(capacity_);
  samples_.resize(w);
  sampled_step_.resize(w);
  stamp_.resize(w);
  z_.resize(w);
  x_.resize(w);
  zeta_.resize(w);
  residual_.resize(w);
  rest_zeta_.resize(w);
  est_.resize(w);
  window_clamped_.assign(w, 0);
  held_.assign(w, 0);
  stand_in_.assign(w, 0);
  c_.resize(w);
  dzp_.resize(w);
  cp_.resize(w);
  y_.resize(w);
  zp_.resize(w);
  xp_.resize(w);
  yp_.resize(w);
  e_.resize(w);
  u_.resize(w);
  w_scratch_.resize(w + 1);
  rhs_.resize(w);
  target_.resize(w);
  diag_.resize(w);
  const bool linear = config.solver == WindowSolver::Linear;
  rot_.adaptive = linear && smoothing_source(config, true) == SmoothingSource::Adaptive;
  pos_.adaptive = linear && smoothing_source(config, false) == SmoothingSource::Adaptive;
  if (rot_.adaptive || pos_.adaptive) {
    levels_.assign(kMaxSmoothingLevels, make_emission_row(capacity_));
    if (config.lag == 0 && config.adaptation.prediction_check) next_rows_.assign(kMaxSmoothingLevels, make_emission_row(capacity_));
    level_tail_bias_.assign(static_cast<std::size_t>(kMaxSmoothingLevels * capacity_), 0.0);
  }
  if (!linear) {
    // The iterative solvers' settings are fixed at construction (validate() made sure they can be).
    rot_.mu = resolvable(config, true) ? fixed_smoothing(config, true, config.rate_hz) : 0.0;
    pos_.mu = resolvable(config, false) ? fixed_smoothing(config, false, config.rate_hz) : rot_.mu;
    if (config.solver == WindowSolver::GaussNewton) {
      // One factorisation per fill level n; samples with index < n-1-L have been emitted.
      factors_r_.resize(w + 1);
      factors_t_.resize(w + 1);
      for (int n = 1; n <= config.window; ++n) {
        for (int i = 0; i < n; ++i) diag_[static_cast<std::size_t>(i)] = 1.0 + (i < n - 1 - config.lag ? config.continuity : 0.0);
        factors_r_[static_cast<std::size_t>(n)] = make_smoothing_system(n, config.order, rot_.mu, std::span(diag_).first(static_cast<std::size_t>(n)));
        factors_t_[static_cast<std::size_t>(n)] = make_smoothing_system(n, config.order, pos_.mu, std::span(diag_).first(static_cast<std::size_t>(n)));
      }
    }
  }
  rate_measured_ = config.rate_hz == 0.0 && needs_rate();
  if (!rate_measured_) prepare(config.rate_hz);
  if (config.continuity > 0.0) {
    if (!linear) builder_.build(config.window, rot_.mu, target_spec_, rot_.fixed);
    check_continuity_stability();
  }
}

bool FairingWindow::needs_rate() const {
  if (config_.solver != WindowSolver::Linear) return false;
  return config_.window == 0 || config_.horizon_s > 0.0 || smoothing_source(config_, true) != SmoothingSource::Given ||
         smoothing_source(config_, false) != SmoothingSource::Given;
}

void FairingWindow::note_interval(double dt) {
  rate_estimate_.note(dt);
  if (rate_estimate_.rate() > 0.0) prepare(rate_estimate_.rate());
}

// A measured rate the stream has left: two blocks of kMaxRateIntervals steps in a row whose
// rates agree with each other and differ from it by more than kRateChange either way (jitter
// moves a block's median by a few per cent, a stream that changes its rate by that ratio).
// Steps the gate calls gaps count too, up to gap_threshold: at a quarter of the rate every
// step is gap_intervals long. Returns the new rate, or 0.
double FairingWindow::rate_change(double step) {
  if (!(step > 0.0) || step > config_.gate.gap_threshold) return 0.0;
  rate_check_.note(step);
  const double r = rate_check_.rate();
  if (r == 0.0) return 0.0;
  rate_check_ = StreamRateEstimate(kMaxRateIntervals);
  const auto within = [](double a, double b, double ratio) { return a < ratio * b && b < ratio * a; };
  if (within(r, rate_, kRateChange)) {
    rate_candidate_ = 0.0;
    return 0.0;
  }
  const bool confirmed = rate_candidate_ > 0.0 && within(r, rate_candidate_, 1.25);
  rate_candidate_ = confirmed ? 0.0 : r;
  return confirmed ? r : 0.0;
}

// The stream's interval: 1/rate once known, before that the estimate's (stream_rate.hpp).
double FairingWindow::typical_interval() const {
  return rate_ > 0.0 ? 1.0 / rate_ : rate_estimate_.typical_interval();
}

// Settles W, the emission rows and the estimators for this rate (0: not needed). Runs at
// construction or after the first intervals, and again, on an empty window, when a measured rate
// changes; the storage exists already, so it allocates nothing.
void FairingWindow::prepare(double rate_hz) {
  rate_ = rate_hz;
  if (rate_hz > 0.0) gate_.set_interval(1.0 / rate_hz);
  const int m = config_.order;
  if (config_.window > 0) {
    w_ = config_.window;
  } else {
    const int shortest = std::max({kMinWindowSamples, config_.lag + 2, m + 1});
    w_ = std::clamp(static_cast<int>(std::lround(config_.window_s * rate_hz)), std::min(shortest, capacity_), capacity_);
  }
  target_spec_.horizon = config_.horizon_s * rate_hz;
  if (config_.solver == WindowSolver::Linear) {
    for (Channel* ch : {&rot_, &pos_}) {
      if (ch->adaptive) continue;
      ch->mu = fixed_smoothing(config_, ch == &rot_, rate_hz);
      builder_.build(w_, ch->mu, target_spec_, ch->fixed);
    }
    if (rot_.adaptive || pos_.adaptive) {
      // Level 0 passes the measurements through; then cutoffs from 0.45 of the rate down, a
      // third of an octave apart, until the smoothing is as heavy as the window can express.
      level_count_ = 0;
      builder_.build(w_, 0.0, target_spec_, levels_[static_cast<std::size_t>(level_count_++)]);
      for (int j = 0; level_count_ < kMaxSmoothingLevels; ++j) {
        const double nu = 0.45 * std::pow(2.0, -j / 3.0);
        const double mu = std::pow(2.0 * std::sin(std::numbers::pi * nu), -2.0 * m);
        if (mu > kMaxSmoothing) break;
        builder_.build(w_, mu, target_spec_, levels_[static_cast<std::size_t>(level_count_++)]);
      }
      rot_.blend.level = pos_.blend.level = -1.0;  // of the rows before
      if (!next_rows_.empty()) {
        // The check's predictions: each level's fit one sample past the newest.
        const EmissionTarget next{m, 0, 1.0, 0.0};
        for (int l = 0; l < level_count_; ++l)
          builder_.build(w_, levels_[static_cast<std::size_t>(l)].mu, next, next_rows_[static_cast<std::size_t>(l)]);
        // Compared where the levels are chosen again (every sample, or every 4 ms at higher rates),
        // at most PredictionCheck::kChecksPerSecond times a second.
        const double evaluations = std::min({rate_hz, MotionNoiseEstimator::kMotionRefreshes / config_.adaptation.motion_time_s,
                                             PredictionCheck::kChecksPerSecond});
        // With a horizon the lightest candidate dead-reckons the measurements, noise and all: the
        // estimate is used from the start (the quality benchmark's 100 Hz set under noise 0.05 at
        // 20 ms lost 2.9% with the lightest first).
        const bool lightest_first = config_.horizon_s == 0.0;
        rot_.check.configure(evaluations, lightest_first);
        pos_.check.configure(evaluations, lightest_first);
      }
      const int k = w_ - 1 - config_.lag;  // the emitted sample
      for (int l = 0; l + 1 < level_count_; ++l)
        level_shared_gain_[static_cast<std::size_t>(l)] =
            shared_noise_gain(levels_[static_cast<std::size_t>(l)], levels_[static_cast<std::size_t>(l + 1)], w_, k);
      // Each level's drag for a motion that stopped c samples back, at its largest for any c' ≥ c:
      // a stop is known only to lie at least c samples back (the fit's span, or its newest half,
      // within the noise), and the drag of the polynomial end tail_bias assumes crosses zero at
      // some c for the heavier levels (level 15 at 250 Hz: 0.0075 at c = 30, 0.73 at 31), where a
      // real turn's end drags all the same (a clean turn at 250 Hz: one pose 0.007 rad off).
      for (int c = w_ - 2; c >= 0; --c)
        for (int l = 0; l < level_count_; ++l) {
          const double here = std::abs(tail_bias(levels_[static_cast<std::size_t>(l)], w_, target_spec_, c));
          const double later = c + 2 < w_ ? level_tail_bias_[static_cast<std::size_t>((c + 1) * kMaxSmoothingLevels + l)] : 0.0;
          level_tail_bias_[static_cast<std::size_t>(c * kMaxSmoothingLevels + l)] = std::max(here, later);
        }
      rot_.estimator.configure(rate_hz, config_.adaptation, w_);
      pos_.estimator.configure(rate_hz, config_.adaptation, w_);
      AdaptationSettings aided = config_.adaptation;
      aided.motion_span_s = w_ / rate_hz;
      aided.motion_time_s = std::max(aided.motion_time_s, aided.motion_span_s);
      aided.motion_floor = false;
      aided_estimator_.configure(rate_hz, aided, w_);
    }
  }
  prepared_ = true;
  if (n_ > w_) slide(n_ - w_);
}

void FairingWindow::adapt(Channel& ch, std::span<const Vec3> zeta, double dt) {
  if (!ch.adaptive || !prepared_) return;
  MotionNoiseEstimator& estimator = &ch == &rot_ && aided_ ? aided_estimator_ : ch.estimator;
  const bool refreshed = estimator.update(zeta, dt, &ch == &rot_ ? rest_increments(static_cast<int>(zeta.size())) : std::span<const Vec3>{},
                                          since_stand_in_);
  if (!estimator.ready()) {
    ch.level = 0.0;
    ch.mu = 0.0;
    return;
  }
  const bool checked = checks_prediction(ch);
  if (checked && estimator.at_rest()) ch.check.note_rest();
  if (checked) {
    compare_predictions(ch, zeta);
    ch.check.state().since_check_s += dt;
  }
  if (!refreshed) return;  // the level follows the motion estimate's refreshes
  ch.filling_moved = false;  // the motion estimate has the samples since the gap
  // A motion that stopped and is still in the window: each level's drag towards it counts too.
  const MotionNoiseEstimator::StoppedMotion stopped = estimator.stopped_motion(w_);
  const std::span<const double> tail =
      stopped.motion_var > 0.0
          ? std::span<const double>(level_tail_bias_).subspan(static_cast<std::size_t>(stopped.clear * kMaxSmoothingLevels),
                                                              static_cast<std::size_t>(level_count_))
          : std::span<const double>{};
  const double margin = config_.adaptation.motion_margin;
  auto level_at = [&](double noise_scale) {
    return best_level(levels_, level_shared_gain_, level_count_, noise_scale * estimator.noise_variance(),
                      margin * estimator.motion_variance(), tail, margin * stopped.motion_var);
  };
  ch.level = level_at(1.0);
  if (checked) {
    // The candidates' levels and predictions, at most PredictionCheck::kChecksPerSecond times a
    // second (at 1 kHz the levels are chosen every 4 ms); in between the one in use only. The
    // same at rest (no motion: the heaviest for any noise), and pass-through once one is (less
    // noise only lightens).
    PredictionCheck::State& s = ch.check.state();
    const double period = 1.0 / PredictionCheck::kChecksPerSecond;
    const bool check = s.since_check_s >= (1.0 - 1e-9) * period;
    ch.candidate_level[0] = ch.level;
    for (int j = 1; j < PredictionCheck::kCandidates; ++j) {
      if (!check && j != ch.check.choice()) continue;
      const double before = ch.candidate_level[static_cast<std::size_t>(j - 1)];
      ch.candidate_level[static_cast<std::size_t>(j)] = estimator.at_rest()         ? ch.level
                                                        : check && before == 0.0 ? 0.0
                                                                                 : level_at(PredictionCheck::scale(j));
    }
    ch.level = ch.candidate_level[static_cast<std::size_t>(ch.check.choice())];
    if (check) {
      // (Its remainder kept, so that a stream whose refreshes are not a multiple of the period is
      // checked kChecksPerSecond times a second on average.)
      s.since_check_s = s.since_check_s >= 2.0 * period ? 0.0 : s.since_check_s - period;
      predict_next(ch, zeta);
    }
  }
  // The μ a window still filling uses, and the one reported: geometric between the levels
  // (linear from the pass-through level 0).
  const int i = static_cast<int>(ch.level);
  const double f = ch.level - i;
  const double a = levels_[static_cast<std::size_t>(i)].mu;
  const double b = i + 1 < level_count_ ? levels_[static_cast<std::size_t>(i + 1)].mu : a;
  ch.mu = f == 0.0 ? a : a > 0.0 ? a * std::pow(b / a, f) : f * b;  // (a whole level, at rest the heaviest: no pow)
}

// The check by the next measurement (prediction_check.hpp): at lag 0, where the adaptation's
// choice is what goes out; not on a gyro-aided rotation (its own estimator, a residual).
bool FairingWindow::checks_prediction(const Channel& ch) const {
  return !next_rows_.empty() && !(&ch == &rot_ && aided_);
}

// The newest measurement against each candidate's prediction of it. Not where the adaptation's
// level is not what went out: at rest (the rest line) or a motion leaving rest (as measured). A
// held sample is compared as the window holds it (hold_outliers: a release puts the check back
// with the adaptation and compares the measurement).
void FairingWindow::compare_predictions(Channel& ch, std::span<const Vec3> zeta) {
  PredictionCheck::State& s = ch.check.state();
  if (!s.predicted) return;
  s.predicted = false;
  if (n_ != w_ || zeta.size() != static_cast<std::size_t>(w_ - 1) || ch.estimator.at_rest() || ch.rest.resting ||
      ch.rest.leaving > 0 || since_stand_in_ < 2)  // (the newest increment reaches a stand-in: not a measurement's)
    return;
  const Vec3& newest = zeta.back();
  std::array<double, PredictionCheck::kCandidates> errors{};
  for (std::size_t j = 0; j < errors.size(); ++j) errors[j] = (newest - s.prediction[j]).squaredNorm() / 3.0;
  ch.check.note(errors);
}

namespace {

// u = Σ_j row.zeta_j ζ_j (+ Σ_i row.c_i c_i over emitted samples).
// A difference e off what the noise of variance noise_var (per component, as it reaches e) could
// put there: its mean square per component over kRestDepartureFactor times that.
bool off_beyond_noise(const Vec3& e, double noise_var) { return e.squaredNorm() / 3.0 > kRestDepartureFactor * noise_var; }

Vec3 apply_row(const EmissionRow& row, int n, std::span<const Vec3> zeta, std::span<const Vec3> c, int emitted, bool continuity) {
  Vec3 e = weighted_vector_sum(row.first, n - 1, [&](int j) { return row.zeta[static_cast<std::size_t>(j)]; }, zeta);
  if (continuity) e += weighted_vector_sum(row.first, emitted, [&](int i) { return row.c[static_cast<std::size_t>(i)]; }, c);
  return e;
}

// The weights on ζ of (1 − f)·u_a + f·u_b (the adapted smoothing between two levels; no
// continuity, which needs fixed smoothing).
double blended_weight(const EmissionRow& a, const EmissionRow& b, double f, int j) {
  return (1.0 - f) * a.zeta[static_cast<std::size_t>(j)] + f * b.zeta[static_cast<std::size_t>(j)];
}

// Those weights applied to ζ in one pass.
Vec3 apply_rows(const EmissionRow& a, const EmissionRow& b, double f, int n, std::span<const Vec3> zeta) {
  return weighted_vector_sum(std::min(a.first, b.first), n - 1, [&](int j) { return blended_weight(a, b, f, j); }, zeta);
}

// Or kept, for a level used on several samples.
void blend_rows(const EmissionRow& a, const EmissionRow& b, double f, int n, std::vector<double>& out) {
  for (int j = std::min(a.first, b.first); j < n - 1; ++j) out[static_cast<std::size_t>(j)] = blended_weight(a, b, f, j);
}

}  // namespace

// Each candidate's prediction of the next measurement, as an increment from the newest (a full
// window, not at rest). Candidates at the same level share one.
void FairingWindow::predict_next(Channel& ch, std::span<const Vec3> zeta) {
  PredictionCheck::State& s = ch.check.state();
  s.predicted = n_ == w_ && zeta.size() == static_cast<std::size_t>(w_ - 1) && !ch.estimator.at_rest();
  if (!s.predicted) return;
  for (std::size_t j = 0; j < s.prediction.size(); ++j) {
    const double level = ch.candidate_level[j];
    if (j > 0 && level == ch.candidate_level[j - 1]) {
      s.prediction[j] = s.prediction[j - 1];
      continue;
    }
    const int i = static_cast<int>(level);
    const EmissionRow& a = next_rows_[static_cast<std::size_t>(i)];
    s.prediction[j] = apply_rows(a, i + 1 < level_count_ ? next_rows_[static_cast<std::size_t>(i + 1)] : a, level - i, n_, zeta);
  }
}

// The level in use's two rows and the blend between them (f: the second's share).
FairingWindow::LevelRows FairingWindow::level_rows(const Channel& ch) const {
  const int i = static_cast<int>(ch.level);
  const EmissionRow& a = levels_[static_cast<std::size_t>(i)];
  return {a, i + 1 < level_count_ ? levels_[static_cast<std::size_t>(i + 1)] : a, ch.level - i};
}

double FairingWindow::correction_gain(const Channel& ch) const {
  return level_rows(ch).blended(&EmissionRow::correction_gain);
}

// What the level in use corrected at the emitted sample k, for the motion estimate
// (MotionNoiseEstimator::note_correction): not where nothing was corrected (level 0, a window
// still filling), where the correction is more than smoothing (a horizon extrapolates), at rest
// (the rest line emits), on a gyro-aided rotation (its own estimator), or for an outlier held.
// Between two levels the bias blends linearly and the gain is taken as blended too (it is
// convex in f, so this is an upper bound: the test errs toward smoothing).
void FairingWindow::note_correction(Channel& ch, int k, const Vec3& u, double dt) {
  if (!ch.adaptive || !prepared_ || (&ch == &rot_ && aided_)) return;
  const char bit = &ch == &rot_ ? kHeldRotation : kHeldPosition;
  const bool learn = n_ == w_ && config_.horizon_s == 0.0 && !ch.estimator.at_rest() && !ch.rest.resting && ch.level > 0.0 &&
                     !((held_[static_cast<std::size_t>(k)] | newest_held_) & bit);
  if (!learn) {
    ch.estimator.note_correction(0.0, 0.0, 0.0, dt);
    return;
  }
  const LevelRows r = level_rows(ch);
  ch.estimator.note_correction(u.squaredNorm() / 3.0, r.blended(&EmissionRow::correction_gain), r.blended(&EmissionRow::bias), dt);
}

Vec3 FairingWindow::linear_correction(Channel& ch, std::span<const Vec3> zeta, std::span<const Vec3> c) {
  if (!prepared_) return Vec3::Zero();  // the rate is not known yet: the measurement passes
  const int emitted = n_ - 1 - config_.lag;
  const bool continuity = config_.continuity > 0.0;
  if (n_ == w_) {
    if (!ch.adaptive) return apply_row(ch.fixed, n_, zeta, c, emitted, continuity);
    const int i = static_cast<int>(ch.level);
    const double f = ch.level - i;
    const EmissionRow& a = levels_[static_cast<std::size_t>(i)];
    if (!(f > 0.0) || i + 1 >= level_count_) return apply_row(a, n_, zeta, c, emitted, false);
    Channel::Blend& blend = ch.blend;
    if (blend.level != ch.level) {
      blend_rows(a, levels_[static_cast<std::size_t>(i + 1)], f, n_, blend.zeta);
      blend.first = std::min(a.first, levels_[static_cast<std::size_t>(i + 1)].first);
      blend.level = ch.level;
    }
    return weighted_vector_sum(blend.first, n_ - 1, [&](int j) { return blend.zeta[static_cast<std::size_t>(j)]; }, zeta);
  }
  // A window still filling (after the start or a gap): its row, built for this fill level.
  if (!ch.filling_moved && fill_moves(ch, zeta)) ch.filling_moved = true;
  const double mu = ch.filling_moved ? 0.0 : ch.mu;
  if (mu == 0.0 && config_.horizon_s == 0.0) return Vec3::Zero();
  builder_.build(n_, mu, target_spec_, fill_row_);
  return apply_row(fill_row_, n_, zeta, c, emitted, continuity);
}

// A window filling again after a gap smooths as the adaptation chose before it (Channel::
// filling_moved): true where that smoothing's estimate of the newest sample stands off it by more
// than the noise could put it (as a sample off the rest line: kRestDepartureFactor), a motion the
// fits cannot see yet. Not for a gyro-aided rotation (its own estimator).
bool FairingWindow::fill_moves(const Channel& ch, std::span<const Vec3> zeta) {
  const MotionNoiseEstimator& e = ch.estimator;
  if (!ch.adaptive || !(ch.mu > 0.0) || !e.ready() || (&ch == &rot_ && aided_)) return false;
  builder_.build(n_, ch.mu, EmissionTarget{config_.order, 0, 0.0, 0.0}, fill_newest_row_);
  const Vec3 u = apply_row(fill_newest_row_, n_, zeta, {}, n_ - 1, false);
  return off_beyond_noise(u, e.noise_variance());
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
  const auto& g = rot_.fixed.c;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(taps, taps);
  // c at window index taps-1 is the newest emitted (one step back), index 0 the oldest.
  for (int j = 1; j <= taps; ++j) companion(0, j - 1) = g[static_cast<std::size_t>(taps - j)];
  for (int j = 1; j < taps; ++j) companion(j, j - 1) = 1.0;
  const double radius = companion.eigenvalues().cwiseAbs().maxCoeff();
  if (!(radius < 1.0 - 1e-9))
    throw InvalidEngineSetting(EngineSetting::Continuity, "continuity " + std::to_string(config_.continuity) + " with smoothing " +
        std::to_string(rot_.mu) + ", window " + std::to_string(w) + " and lag " +
        std::to_string(lag) + " makes the output recursion unstable (spectral radius " +
        std::to_string(radius) + "); lower the continuity or the smoothing");
}

EngineState FairingWindow::state() const {
  EngineState s;
  s.rate_hz = rate_;
  s.window = w_;
  s.repeating = repeating_;
  s.slerped = slerped_;
  const double dt = rate_ > 0.0 ? 1.0 / rate_ : 0.0;
  s.gyro = gyro_.state(aided_);
  for (const bool rotation : {true, false}) {
    const Channel& ch = rotation ? rot_ : pos_;
    ChannelAdaptation& out = rotation ? s.rotation : s.position;
    // Rotation channels work in half-angle vectors (so3::log): twice that is the angle.
    const double unit = rotation ? 2.0 : 1.0;
    out.adaptive = ch.adaptive;
    out.smoothing = ch.mu;
    out.cutoff_hz = cutoff_for_smoothing(ch.mu, rate_, config_.order);
    if (ch.adaptive) {
      const MotionNoiseEstimator& estimator = rotation && aided_ ? aided_estimator_ : ch.estimator;
      out.noise = unit * std::sqrt(3.0 * estimator.noise_variance());
      out.rest_noise = unit * std::sqrt(3.0 * estimator.rest_noise_variance());
      out.at_rest = estimator.at_rest();
      out.motion = dt > 0.0 ? unit * std::sqrt(3.0 * estimator.motion_variance()) / std::pow(dt, config_.order) : 0.0;
      out.rest_averaged = ch.rest.averaged;
      if (checks_prediction(ch)) out.noise_scale = ch.check.scale();
    }
  }
  return s;
}

void FairingWindow::linear_emission_estimate(int k, double dt) {
  const auto d = static_cast<std::size_t>(std::max(0, n_ - 1));
  // Tested on the rest line before the newest sample goes into it.
  const Departure rot_departs = k == n_ - 1 ? departs_from_rest(rot_) : Departure::None;
  const Departure pos_departs = positions_ && k == n_ - 1 ? departs_from_rest(pos_) : Departure::None;
  adapt(rot_, std::span<const Vec3>(rotation_increments()).first(d), dt);
  if (positions_) adapt(pos_, std::span<const Vec3>(dzp_).first(d), dt);
  follow_rest(rot_, rot_departs != Departure::None);
  if (positions_) follow_rest(pos_, pos_departs != Departure::None);
  if (k < 0) return;
  const auto i = static_cast<std::size_t>(k);
  // A motion leaving rest goes out as measured (k is the newest sample, and there is no horizon).
  auto correction = [&](Channel& ch, std::span<const Vec3> zeta, std::span<const Vec3> c, Departure departs) -> Vec3 {
    if (departs == Departure::Moving) {
      ch.rest.leaving = ch.estimator.span();
      note_correction(ch, k, Vec3::Zero(), dt);
      return Vec3::Zero();
    }
    if (ch.rest.resting && ch.rest.leaving == 0) {
      // At rest nothing is learned from the correction (note_correction), and once the rest line's
      // weight is whole the window's correction has no part in the output: it is not computed (a
      // row over the whole window, the largest part of the engine's cost at rest).
      note_correction(ch, k, Vec3::Zero(), dt);
      const RestPart rest = rest_part(ch, k, dt);
      return rest.weight == 1.0 ? rest.pose : rest.over(linear_correction(ch, zeta, c));
    }
    const Vec3 u = linear_correction(ch, zeta, c);
    note_correction(ch, k, u, dt);
    // The motion estimate takes a motion out of rest from its fits, which see its start dimly for
    // a few samples more (at most the fit's span); meanwhile the level chosen lags it. Where the
    // level's correction stands off the measurement by more than the noise could put it (as a
    // departure from the line does), the sample still goes out as measured, and the correction
    // it would have made is noted all the same (kBiasFactor: it is motion the estimate missed).
    // The first within the noise ends that.
    if (ch.rest.leaving > 0) {
      --ch.rest.leaving;
      if (departs == Departure::None && n_ == w_ &&
          off_beyond_noise(u, ch.estimator.noise_variance() * correction_gain(ch)))
        return Vec3::Zero();
      ch.rest.leaving = 0;
    }
    return rest_part(ch, k, dt).over(u);
  };
  est_[i] = correction(rot_, rotation_increments(), c_, rot_departs);
  if (positions_) xp_[i] = zp_[i] + correction(pos_, dzp_, cp_, pos_departs);
}

// At rest, the rotation's count newest increments on the rest line's chart, for the rest test's
// line (none otherwise). Summed, the increments ζ = log(z_j⁻¹z_{j+1}) carry second-order
// (Baker–Campbell–Hausdorff) terms that walk, as the rest line's coordinate did: under noise of
// bound 0.04 (0.08 rad of angle) at 250 Hz the line's slope walked out of rest 8% of the time.
// On the chart the walk is gone. All of them when the rest (or its reference) is new or an
// outlier was released (hold_outliers); then the newest, two logs per sample.
std::span<const Vec3> FairingWindow::rest_increments(int count) {
  if (aided_ || !rot_.rest.resting || count < 2) {
    rest_chart_ready_ = false;
    return {};
  }
  const Quat& r = rot_.rest.reference;
  auto coordinate = [&](int j) { return rest_coordinate(rot_, j); };
  const bool fresh = !rest_chart_ready_ || rest_chart_reference_.coeffs() != r.coeffs();
  const int from = fresh ? 0 : count - 1;
  Vec3 before = coordinate(from);
  for (int j = from; j < count; ++j) {
    const Vec3 here = coordinate(j + 1);
    rest_zeta_[static_cast<std::size_t>(j)] = here - before;
    before = here;
  }
  rest_chart_reference_ = r;
  rest_chart_ready_ = true;
  return std::span<const Vec3>(rest_zeta_).first(static_cast<std::size_t>(count));
}

// At rest on the rest line: where the newest sample lands from the line's prediction for it (a
// held one: only as it is emitted, as measured at lag 0). Off it by more than the noise could put
// it, it is kept out of the line; off it twice running, on the same side, it is a motion starting
// (a noise spike, which a heavy-tailed noise has now and then, is alone) and is emitted
// unsmoothed: the line would hold it at the still pose until the motion estimate takes the
// motion, after its fit has stood over the onset threshold twice. The first off the line is
// emitted unsmoothed too where the stream's first samples off it have mostly begun motions
// (Channel::Departures). Not while predicting: the level-0 prediction carries one noisy step over
// the horizon, worse than the line (quality benchmark, rests set at 20 ms: +0.9%).
FairingWindow::Departure FairingWindow::departs_from_rest(Channel& ch) {
  const Vec3 before = ch.rest.departure;  // zero unless the sample before was off the line
  ch.rest.departure = Vec3::Zero();
  const auto newest = static_cast<std::size_t>(n_ - 1);
  const double time = samples_[newest].time;
  Channel::Departures& d = ch.departures;
  // The first sample after one that was the first off the line tells what that one was (once:
  // a held sample's estimate is made again when it is put back or released).
  const bool judging = time > d.first_off_time;
  if (judging) d.first_off_time = std::numeric_limits<double>::infinity();
  auto judged = [&](bool start) {
    if (!judging) return;
    d.starts *= kDepartureMemory;
    d.spikes *= kDepartureMemory;
    (start ? d.starts : d.spikes) += 1.0;
    if (start) d.start_square = std::max(kDepartureMemory * d.start_square, d.first_off_square);
  };
  const char held = &ch == &rot_ ? kHeldRotation : kHeldPosition;
  if (config_.horizon_s > 0.0 || !ch.adaptive || n_ != w_ || since_stand_in_ == 0) return Departure::None;  // (a stand-in measures nothing)
  if ((newest_held_ & held) != 0 && !emitting_held_) {
    judged(false);  // the guard holds it: alone, or a burst
    return Departure::None;
  }
  if (!ch.rest.resting) {
    judged(true);  // rest ended with it: the motion estimate took the motion
    return Departure::None;
  }
  const std::optional<Vec3> off = from_rest_line(ch);
  if (!off) return Departure::None;
  const Vec3 e = *off;
  if (!off_beyond_noise(e, ch.estimator.noise_variance())) {
    judged(false);
    return Departure::None;
  }
  ch.rest.departure = e;
  // Two in a row on one side are a motion starting. Where the noise has risen lately (a burst,
  // which puts two in a row on one side about one time in five), only if their mean stands beyond
  // that noise too (as a mean of two, half its variance): each such pair went out as measured.
  const double risen = ch.estimator.rest_noise_variance();
  const bool moving = e.dot(before) > 0.5 * before.squaredNorm() &&
                      (!(risen > ch.estimator.noise_variance()) || off_beyond_noise(0.5 * (e + before), 0.5 * risen));
  judged(moving);
  if (moving) return Departure::Moving;
  d.first_off_time = time;
  d.first_off_square = e.squaredNorm();
  // Held at the still pose, a motion's first sample costs what a spike let through does: so it
  // goes out as measured where the first samples off the line have more often begun motions, and
  // it is no further off than theirs (kDepartureReach times the furthest): a glitch far beyond a
  // motion's first step is not taken for one.
  const bool like_a_start = d.starts > d.spikes && d.first_off_square <= kDepartureReach * kDepartureReach * d.start_square;
  return like_a_start ? Departure::Moving : Departure::Off;
}

// Where the newest sample lands from the rest line's prediction for it (none where the line has
// none).
std::optional<Vec3> FairingWindow::from_rest_line(const Channel& ch) const {
  const std::optional<Vec3> line = ch.rest.line.line_at(ch.rest.time - samples_[static_cast<std::size_t>(n_ - 1)].time);
  if (!line) return std::nullopt;
  return rest_coordinate(ch, n_ - 1) - *line;
}

// Sample j in the rest line's coordinate, from the rest's first sample: positions, p_j − p_0;
// rotations, log(R⁻¹z_j) with R its pose. Not the sum of the rotation increments since then:
// each pair of noisy increments adds a term of the order of their product, and over seconds of
// a noisy 1 kHz stream the terms walk far enough to bend the line (test
// Adaptation.AStillPoseUnderHeavyNoiseIsAveragedToo).
Vec3 FairingWindow::rest_coordinate(const Channel& ch, int j) const {
  const auto i = static_cast<std::size_t>(j);
  if (&ch != &rot_) return zp_[i] - ch.rest.origin;
  const Eigen::Vector4d& r = ch.rest.reference.coeffs();
  const Eigen::Vector4d& z = z_[i].coeffs();
  for (const RestChartMemo& m : rest_chart_memo_)
    if (m.z == z && m.reference == r) return m.coordinate;
  RestChartMemo& m = rest_chart_memo_[rest_chart_memo_next_];
  rest_chart_memo_next_ = (rest_chart_memo_next_ + 1) % rest_chart_memo_.size();
  m = {r, z, so3::log(ch.rest.reference.conjugate() * z_[i])};
  return m.coordinate;
}

// At rest, the channel's samples also feed a line with a memory of seconds (rest_line.hpp),
// taken while no motion is seen (the heaviest level), in rest_coordinate.
void FairingWindow::follow_rest(Channel& ch, bool departs) {
  const double memory = config_.adaptation.rest_memory_s;
  // A rest goes on while the window fills again after a gap (the still pose is the same after
  // it); one begins on a full window only.
  const bool still = ch.adaptive && prepared_ && memory > 0.0 && !(&ch == &rot_ && aided_) && (n_ == w_ || ch.rest.resting) &&
                     ch.estimator.at_rest();
  if (!still) {
    ch.rest.resting = false;
    return;
  }
  auto feed = [&](int from) {
    for (int i = from; i < n_; ++i) {
      const auto j = static_cast<std::size_t>(i);
      // A stand-in for a lost sample is no measurement: its noise is its neighbours', which the
      // line's test of straightness would count twice.
      if (stand_in_[j]) continue;
      const bool first = ch.rest.line.empty();
      if (first) {
        ch.rest.reference = z_[j];
        if (&ch == &pos_) ch.rest.origin = zp_[j];
      }
      // From the last sample the line took (a sample off it is skipped).
      // Weighed by the inverse of its noise: a sample taken in a burst of noise counts for less.
      ch.rest.line.add(first ? 0.0 : samples_[j].time - ch.rest.time, rest_coordinate(ch, i), memory,
                       ch.estimator.noise_variance() / ch.estimator.rest_noise_variance());
      ch.rest.time = samples_[j].time;
    }
  };
  if (ch.rest.resting) {
    // Filling again after a gap (which the departure rules do not judge), the rest goes on while
    // the samples stay on the line; one off it ends it (the tracker moved in the gap, or now).
    if (n_ != w_ && since_stand_in_ > 0) {
      const std::optional<Vec3> off = from_rest_line(ch);
      if (!off || off_beyond_noise(*off, ch.estimator.noise_variance())) {
        ch.rest.resting = false;
        return;
      }
    }
    if (!departs) feed(n_ - 1);  // a sample that left the still pose is no part of it
    return;
  }
  // The rest begins again. Where the rest test let go of it only for a moment (the window's
  // slope is noisy too, so it does now and then), the line takes the samples it missed from the
  // window and goes on, if it is still straight; otherwise it starts afresh. Either only from the
  // samples the rest test's line spans: the window's, or after a motion stopped those clear of it
  // (an earlier rest's last sample may still be in the window, before the motion).
  const int first = std::max(0, n_ - ch.estimator.rest_span());
  int last = -1;
  if (!ch.rest.line.empty())
    for (int i = n_ - 1; i >= first && last < 0; --i)
      if (samples_[static_cast<std::size_t>(i)].time == ch.rest.time) last = i;
  if (last >= 0) feed(last + 1);
  const std::optional<RestLine::Value> value = ch.rest.line.value_at(0.0, ch.estimator.rest_noise_variance(), kRestLineFactor);
  if (last < 0 || !value || !value->straight) {
    ch.rest.line.reset();
    feed(first);
  }
  ch.rest.resting = true;
}

// Sample k's correction (in its chart, as linear_correction's): the window's, moved toward the
// rest line's while the line is straight, and back while it is not, over motion_time_s (a
// switch would step the output, and a stream at the edge of rest switches often). A motion
// seen at rest takes the window's at once, as leaving rest does. Here the line's weight is
// followed and its pose taken; RestPart::over puts it over the window's.
FairingWindow::RestPart FairingWindow::rest_part(Channel& ch, int k, double dt) {
  ch.rest.averaged = false;
  // The line's ages count from the last sample it took (the newest, unless that one was off it).
  const double age = ch.rest.time - samples_[static_cast<std::size_t>(k)].time - config_.horizon_s;
  // A motion the estimate reads at rest keeps the line out until a fit reads none. Not while the
  // window fills again after a gap: no fit comes until it is full, so the estimate is the last
  // one before the gap (now and then a chance reading of the noise, which then held the line off
  // for the whole fill), and the rest goes on only while the samples stay on the line
  // (follow_rest), which is the test that counts then.
  const bool moving = ch.estimator.motion_variance() > 0.0 && n_ == w_;
  const std::optional<RestLine::Value> value =
      ch.rest.resting && !moving ? ch.rest.line.value_at(age, ch.estimator.rest_noise_variance(), kRestLineFactor) : std::nullopt;
  if (!value) {
    // The output takes the window's at once, but the line's weight is given up only where the
    // motion is read twice running: at rest a single fit reads the noise as a motion now and then,
    // and the weight took 0.7 s to come back (docs/engine.md, "At rest").
    if (!(ch.rest.resting && moving && !ch.estimator.motion_read_twice_at_rest())) ch.rest.weight = 0.0;
    return {};
  }
  ch.rest.averaged = value->straight;
  const double target = value->straight ? 1.0 : 0.0;
  if (ch.rest.weight != target)
    ch.rest.weight += (target - ch.rest.weight) * (1.0 - std::exp(-std::max(dt, 0.0) / config_.adaptation.motion_time_s));
  // Within kWholeRest of whole it is whole (after 6.9 motion_time_s of a straight line): the
  // window's part would move the pose by that share of its distance from the line's pose, a few
  // thousandths of the noise, and then need not be computed (RestPart).
  if (target == 1.0 && 1.0 - ch.rest.weight < kWholeRest) ch.rest.weight = 1.0;
  if (!(ch.rest.weight > 0.0)) return {};
  if (&ch == &rot_) {  // the still pose, R·exp(pose), in sample k's chart
    const auto i = static_cast<std::size_t>(k);
    return {ch.rest.weight, so3::log(z_[i].conjugate() * (ch.rest.reference * so3::exp(value->pose)))};
  }
  return {ch.rest.weight, value->pose - rest_coordinate(ch, k)};
}

// Constant angular (and linear) velocity from the last accepted measurement to the newest,
// over their real time step, carried on for the horizon: what dead reckoning predicts. Before
// the rate is known the window has no rows to predict with, and a window restarted by a gap
// has a single sample; holding the measurement there would lag by the whole horizon.
void FairingWindow::predict_from_last_step(int k, double step) {
  if (!(step > 0.0)) return;
  const auto i = static_cast<std::size_t>(k);
  const double s = config_.horizon_s / step;
  est_[i] = s * so3::log(so3::aligned_to(last_z_, z_[i]).conjugate() * z_[i]);
  if (positions_ && last_has_position_) xp_[i] = zp_[i] + s * (zp_[i] - last_p_);
}

std::size_t FairingWindow::memory_bytes() const {
  std::size_t bytes = sizeof(*this);
  bytes += samples_.capacity() * sizeof(Sample);
  bytes += (z_.capacity() + x_.capacity() + y_.capacity() + target_.capacity()) * sizeof(Quat);
  bytes += (zeta_.capacity() + residual_.capacity() + rest_zeta_.capacity() + est_.capacity() + c_.capacity() + dzp_.capacity() + cp_.capacity()) * sizeof(Vec3);
  bytes += (zp_.capacity() + xp_.capacity() + yp_.capacity() + e_.capacity() + u_.capacity() + w_scratch_.capacity() +
            rhs_.capacity()) * sizeof(Vec3);
  bytes += (diag_.capacity() + sampled_step_.capacity() + stamp_.capacity()) * sizeof(double) + window_clamped_.capacity() + held_.capacity() +
           stand_in_.capacity();
  auto row_bytes = [](const EmissionRow& r) { return (r.zeta.capacity() + r.c.capacity()) * sizeof(double); };
  bytes += levels_.capacity() * sizeof(EmissionRow) + level_tail_bias_.capacity() * sizeof(double);
  for (const EmissionRow& r : levels_) bytes += row_bytes(r);
  bytes += next_rows_.capacity() * sizeof(EmissionRow);
  for (const EmissionRow& r : next_rows_) bytes += row_bytes(r);
  bytes += row_bytes(fill_row_) + row_bytes(fill_newest_row_) + row_bytes(rot_.fixed) + row_bytes(pos_.fixed);
  bytes += (rot_.blend.zeta.capacity() + pos_.blend.zeta.capacity()) * sizeof(double);
  // The builder's band matrix and scratch, and the three estimators' fit, half-span fit, window
  // fit and the two lines' weights (newest_line_slope).
  bytes += static_cast<std::size_t>(capacity_) * (static_cast<std::size_t>(config_.order + 1) + 5) * sizeof(double) +
           static_cast<std::size_t>(capacity_ + 1) * sizeof(Vec3) + 3 * 5 * static_cast<std::size_t>(capacity_) * sizeof(double);
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
  const Sample& s = samples_[k];
  // The bound is on the measurement, a held outlier's too (z_ holds its prediction).
  const char held = held_[k];
  bool clamped = project_rotation((held & kHeldRotation) ? so3::aligned_to(s.orientation, z_[k]) : z_[k], q, config_.epsilon_r);
  // The stream stays hemisphere-continuous across window restarts too.
  if (have_emitted_) q = so3::aligned_to(q, last_emitted_);
  last_emitted_ = q;
  have_emitted_ = true;
  // The linear solver's continuity term needs the emitted correction log(z⁻¹ y).
  if (config_.solver == WindowSolver::Linear && config_.continuity > 0.0) c_[k] = so3::log(z_[k].conjugate() * q);
  Vec3 p = xp_[k];
  if (positions_) clamped = project_position((held & kHeldPosition) ? s.position : zp_[k], p, config_.epsilon_t) || clamped;
  if (positions_ && config_.solver == WindowSolver::Linear && config_.continuity > 0.0) cp_[k] = p - zp_[k];
  // With the window policy the projection may already have happened inside the solve.
  clamped = clamped || window_clamped_[k];
  if (clamped) ++counters_.clamped;
  y_[k] = q;
  yp_[k] = p;
  ++counters_.emitted;
  FairedPose out;
  out.stream_id = s.stream_id;
  out.sequence = s.sequence;
  out.time = stamp_[k] + config_.horizon_s;  // a prediction is stamped with the time it is for
  out.orientation = q;
  out.position = positions_ ? p : Vec3::Zero();
  out.measured = s.orientation;
  out.measured_position = s.position;
  out.flags = s.flags | (clamped ? kClamped : 0u) | (held != 0 ? kHeld : 0u);
  out.step = sampled_step_[k];
  return out;
}

int FairingWindow::emit_pending(std::span<FairedPose> out) {
  int count = 0;
  // The linear solver keeps no estimates between samples: solve the whole window once here.
  if (config_.solver == WindowSolver::Linear && first_unemitted() < n_) solve();
  for (int i = first_unemitted(); i < n_; ++i)
    if (!stand_in_[static_cast<std::size_t>(i)]) out[static_cast<std::size_t>(count++)] = emit(i);
  n_ = 0;
  rot_.filling_moved = pos_.filling_moved = false;
  return count;
}

int FairingWindow::flush(std::span<FairedPose> out) { return emit_pending(out); }

// Repeats are carried forward at lag 0 only (with a lag the poses are the window's L samples
// back, and a repeat has no place among them), and where the rate is measured (a rate given is
// the one the window keeps).
bool FairingWindow::carries_repeats() const { return config_.lag == 0 && rate_measured_ && !aided_; }

// The stream started or stopped repeating its measurements (repeated_measurements.hpp): to the
// window it is another stream, at another rate and with another noise per sample, so it starts
// as a new stream does: its rate measured again, and nothing the adaptation learnt kept.
int FairingWindow::start_afresh(std::span<FairedPose> out) {
  const int count = n_ > 0 ? emit_pending(out) : 0;
  ++counters_.restarts;
  // The next pose's step is still from the last one (the gate forgets it below).
  afresh_from_ = carried_time_ >= 0.0 ? carried_time_ : (window_poses_.count > 0 ? window_poses_.time[1] : -1.0);
  window_poses_.count = 0;
  carried_time_ = -1.0;
  gate_.restart();
  gate_.set_interval(0.0);
  have_time_ = false;
  rate_ = 0.0;
  prepared_ = false;
  rate_estimate_ = StreamRateEstimate();
  rate_check_ = StreamRateEstimate(kMaxRateIntervals);
  rate_candidate_ = 0.0;
  for (Channel* ch : {&rot_, &pos_}) {
    ch->estimator.restore({});
    ch->rest = Channel::Rest{};
    ch->departures.first_off_time = std::numeric_limits<double>::infinity();
    ch->mu = 0.0;
    ch->level = 0.0;
    ch->check.restart();
  }
  rest_chart_ready_ = false;
  rot_guard_ = OutlierGuard(outlier_threshold(config_), 0.5);
  pos_guard_ = OutlierGuard(outlier_threshold(config_), 1.0);
  return count;
}

// How much of a step Δ between the window's last two poses to carry on to a repeat: one more
// than three times their noise's standard deviation is motion, carried whole; within that, the
// Wiener weight |Δ|²/(|Δ|² + E|n|²), n the two poses' noise (per component σ² times the level's
// noise gain, each; their correlation left out, so E|n|² errs high). Carrying a step of noise on
// adds it again: a still stream faired from few measurements had 1.4 times its measurements'
// error on its repeats. Before the rate is known the poses are measurements, and a motion's
// steps are carried as before (holding costs a moving stream more than carrying noise costs a
// still one); a fixed μ carries its steps too.
double FairingWindow::carried_share(const Channel& ch, const Vec3& step) const {
  if (!ch.adaptive || !prepared_) return 1.0;
  const double noise = 2.0 * 3.0 * ch.estimator.noise_variance() * level_rows(ch).blended(&EmissionRow::noise_gain);
  const double d2 = step.squaredNorm();
  if (d2 > kClearStep * noise) return 1.0;
  return d2 > 0.0 ? d2 / (d2 + noise) : 0.0;
}

// The motion of the window's last two poses, carried on to the repeat's time, for at most one
// interval of the source (a repeat later than that is a source that stalled: held, not
// extrapolated); a slerped sample before the newest pose's time, interpolated between the two.
// Bounded by ε around the measurement, as every pose.
FairedPose FairingWindow::carry_forward(const Sample& s) {
  const WindowPoses& w = window_poses_;
  // None yet, or one ahead of the sample (a slerped stream's start): as measured.
  const bool measured = w.count == 0 || (w.count == 1 && s.time < w.time[1]);
  Quat q = measured ? s.orientation : w.orientation[1];
  Vec3 p = measured ? s.position : w.position[1];
  if (w.count >= 2 && w.time[1] > w.time[0]) {
    const double ahead = std::max(std::min(s.time - w.time[1], typical_interval()) / (w.time[1] - w.time[0]), -1.0);
    const Vec3 turn = so3::log(w.orientation[0].conjugate() * q);
    const Vec3 move = p - w.position[0];
    // Ahead, each channel's step only as far as it stands clear of the poses' noise; between
    // the two poses (a slerped sample) it is interpolated.
    q = (q * so3::exp(ahead * (ahead > 0.0 ? carried_share(rot_, turn) : 1.0) * turn)).normalized();
    p += ahead * (ahead > 0.0 && positions_ ? carried_share(pos_, move) : 1.0) * move;
  }
  bool clamped = project_rotation(so3::aligned_to(s.orientation, q), q, config_.epsilon_r);
  if (have_emitted_) q = so3::aligned_to(q, last_emitted_);
  last_emitted_ = q;
  if (positions_) clamped = project_position(s.position, p, config_.epsilon_t) || clamped;
  if (clamped) ++counters_.clamped;
  ++counters_.emitted;
  FairedPose out;
  out.stream_id = s.stream_id;
  out.sequence = s.sequence;
  out.time = s.time + config_.horizon_s;
  out.orientation = q;
  out.position = positions_ ? p : Vec3::Zero();
  out.measured = s.orientation;
  out.measured_position = s.position;
  out.flags = s.flags | (clamped ? kClamped : 0u);
  out.step = s.time - (carried_time_ >= 0.0 ? carried_time_ : afresh_from_ >= 0.0 ? afresh_from_ : w.time[1]);
  carried_time_ = s.time;
  afresh_from_ = -1.0;
  return out;
}

// A pose the window emitted at lag 0, for the repeats after it; its step is from the pose
// before it, a carried repeat's if there was one.
void FairingWindow::note_window_pose(FairedPose& pose, double time) {
  if (config_.lag != 0) return;
  if (carried_time_ >= 0.0) pose.step = time - carried_time_;
  if (afresh_from_ >= 0.0) pose.step = time - afresh_from_;
  carried_time_ = afresh_from_ = -1.0;
  WindowPoses& w = window_poses_;
  w.orientation[0] = w.orientation[1];
  w.position[0] = w.position[1];
  w.time[0] = w.time[1];
  w.orientation[1] = pose.orientation;
  w.position[1] = pose.position;
  w.time[1] = time;
  w.count = std::min(w.count + 1, 2);
}

int FairingWindow::push(const Sample& sample, std::span<FairedPose> out) {
  // A stream read faster than its source updates repeats each measurement: the window takes the
  // measurements alone (their rate is the source's) and each repeat is carried forward
  // (repeated_measurements.hpp). One slerped from a slower source holds its measurements on the
  // lines between them: the window takes those, and each sample is interpolated between the
  // poses faired for them (slerped_measurements.hpp).
  int count = 0;
  const bool repeat = repeats_.note(sample);
  SlerpKnot next;
  const bool found = carries_repeats() && slerps_.note(sample, next);  // not read otherwise
  if (carries_repeats()) {
    const bool repeating = repeats_.repeating();
    const bool slerped = !repeating && slerps_.slerped();
    if (repeating != repeating_ || slerped != slerped_) {
      repeating_ = repeating;
      slerped_ = slerped;
      count = start_afresh(out);
    }
  }
  if (repeating_ && repeat && window_poses_.count > 0 && sample.time > last_time_ &&
      sample.time - last_time_ <= config_.gate.gap_threshold) {
    ++counters_.repeated;
    out[static_cast<std::size_t>(count++)] = carry_forward(sample);
    return count;
  }
  // A sample the gate would not accept goes to it, to be counted and dropped.
  if (slerped_ && gate_.validity(sample) == GateVerdict::Accept && sample.time > slerp_time_) {
    Sample s = sample;
    s.orientation.normalize();
    return count + interpolate_slerped(s, found ? &next : nullptr, out.subspan(static_cast<std::size_t>(count)));
  }
  return count + fair(sample, out.subspan(static_cast<std::size_t>(count)));
}

// A sample of a slerped stream: the measurement it shows (the next one, ahead of it) faired
// first, then the sample interpolated between the poses faired for the measurements about it. The
// measurement's own pose is not delivered (nor counted as emitted or clamped): the samples are.
int FairingWindow::interpolate_slerped(const Sample& sample, const SlerpKnot* next, std::span<FairedPose> out) {
  if (next != nullptr && next->time > last_time_) {
    Sample m = sample;
    m.time = next->time;
    m.orientation = next->orientation;
    m.position = next->position;
    std::array<FairedPose, 1> measurement_pose;  // at lag 0 (carries_repeats) one pose per sample at most
    const WindowCounters counted = counters_;
    const double carried = carried_time_, afresh = afresh_from_;
    fair(m, measurement_pose);
    counters_.emitted = counted.emitted;
    counters_.clamped = counted.clamped;
    ++counters_.slerp_measurements;
    carried_time_ = carried;  // the delivered poses' steps are from the sample before
    afresh_from_ = afresh;
  }
  ++counters_.interpolated;
  slerp_time_ = sample.time;
  out[0] = carry_forward(sample);
  return 1;
}

int FairingWindow::fair(const Sample& sample, std::span<FairedPose> out) {
  int count = 0;
  Sample s = sample;
  const GateVerdict verdict = gate_.check(s);
  if (verdict != GateVerdict::Accept && verdict != GateVerdict::AcceptAfterGap) return count;
  const double step = have_time_ ? s.time - last_time_ : 0.0;  // across a gap too
  const double new_rate = prepared_ && rate_measured_ ? rate_change(step) : 0.0;
  // A gap, a change of rate, or a change between samples with and without positions or gyro,
  // starts a new window; a gyro-aided window bridges a few missing readings instead (gyro_aiding.hpp).
  const bool bridge = aided_ && missing_gyro_run_ < kMaxBridgedGyroReadings;
  if (n_ > 0 && (verdict == GateVerdict::AcceptAfterGap || new_rate > 0.0 || s.has_position() != positions_ ||
                 (gyro_aided(s) != aided_ && !bridge))) {
    count += emit_pending(out.subspan(static_cast<std::size_t>(count)));
    ++counters_.restarts;
    window_poses_.count = 0;
  }
  if (new_rate > 0.0) {
    ++counters_.rate_changes;
    prepare(new_rate);
  }
  sampled_offset_ += gate_.sampled_step() - step;  // exactly 0 while the stamps are the sampled times
  double dt = verdict == GateVerdict::Accept ? step : 0.0;
  const bool had_last = have_time_;
  last_time_ = s.time;
  have_time_ = true;
  Quat held_z;
  Vec3 held_p;
  char held = 0;
  const bool linear = config_.solver == WindowSolver::Linear;
  newest_held_ = 0;
  const bool hold = hold_outliers(s, dt > 0.0 ? gate_.sampled_step() : 0.0, held_z, held_p, held);
  newest_held_ = held;
  before_hold_dt_ = -1.0;
  // At lag 0 a held sample is emitted before the next one can release it, and a sudden
  // motion's first sample looks just like an outlier: so it is emitted as the window would
  // emit the measurement, and the prediction takes its place only after (put_held below), for
  // the poses after it and what the adaptation learns. Not the rest of a burst: each of those
  // follows a held sample it did not release, which a motion's next sample would have.
  const bool burst = (!(held & kHeldRotation) || rot_guard_.continues_burst()) &&
                     (!(held & kHeldPosition) || pos_guard_.continues_burst());
  const bool emit_measured = hold && emits_held_as_measured(config_) && !burst;
  if (hold) {
    ++counters_.held;
    rot_before_hold_ = learnt(rot_);
    pos_before_hold_ = learnt(pos_);
    before_hold_dt_ = dt;
  }
  // A step that lost a sample or a few (a radio tracker's lost packets) would be one step to the
  // window, a jump in the motion's every difference: the lost ones are stood in for first. Not
  // before a held sample (the line would lead to its prediction, and a release could not take them
  // back).
  note_step_grid(dt);
  if (const int lost = hold || !(dt > 0.0) ? 0 : lost_in_step(dt); lost > 0) {
    const double each = dt / (lost + 1);
    for (int j = 1; j <= lost; ++j)
      count += stand_in(s, static_cast<double>(j) / (lost + 1), each, out.subspan(static_cast<std::size_t>(count)));
    dt = each;
  }
  if (hold && !emit_measured) {
    Sample h = s;
    h.orientation = held_z;
    h.position = held_p;
    append(h);
    const auto k = static_cast<std::size_t>(n_ - 1);
    samples_[k].orientation = s.orientation;  // emitted as measured, and bounded by it
    samples_[k].position = s.position;
    held_[k] = held;
  } else {
    append(s);
  }
  if (!prepared_) note_interval(dt);
  const int k = n_ - 1 - config_.lag;
  if (linear) {
    // Only the emitted sample's estimate is needed: one precomputed dot product (two while
    // the adapted smoothing lies between levels).
    emitting_held_ = emit_measured;
    linear_emission_estimate(k, dt);
    emitting_held_ = false;
    // A prediction the window cannot make (its rate not yet known, or its only sample the
    // first after a gap) is the last step carried on at its real duration: dead reckoning.
    // Never over a step shorter than the stream's interval (the rate, or before it is known the
    // estimate's): a sample stamped just behind the last, as a burst of reports read together
    // gets, would otherwise blow its noise up by horizon / step; and while nothing says how
    // long a step really took (the clump of a first read), not at all.
    if (config_.horizon_s > 0.0 && k >= 0 && had_last && (!prepared_ || n_ == 1)) {
      const double carried = std::max(step, typical_interval());
      if (carried >= kShortestSampleInterval) predict_from_last_step(k, carried);
    }
  } else {
    solve();
  }
  last_z_ = z_[static_cast<std::size_t>(n_ - 1)];
  last_p_ = s.position;
  last_has_position_ = s.has_position();
  if (k >= 0 && !stand_in_[static_cast<std::size_t>(k)]) {
    out[static_cast<std::size_t>(count)] = emit(k);
    note_window_pose(out[static_cast<std::size_t>(count++)], s.time);
  }
  if (emit_measured) put_held(held_z, held_p, held, dt);
  return count;
}

// Lag 0: the newest sample, just emitted as measured, takes the prediction it was held at, and
// the adaptation learns from that instead.
void FairingWindow::put_held(const Quat& z, const Vec3& p, char held, double dt) {
  const auto k = static_cast<std::size_t>(n_ - 1);
  if (held & kHeldRotation) {
    z_[k] = z;
    if (k > 0) zeta_[k - 1] = so3::log(z_[k - 1].conjugate() * z);
    if (config_.continuity > 0.0) c_[k] = so3::log(z.conjugate() * y_[k]);
  }
  if (positions_ && (held & kHeldPosition)) {
    zp_[k] = p;
    if (k > 0) dzp_[k - 1] = p - zp_[k - 1];
    if (config_.continuity > 0.0) cp_[k] = yp_[k] - p;
  }
  held_[k] = held;
  last_z_ = z_[k];
  restore(rot_, rot_before_hold_);
  restore(pos_, pos_before_hold_);
  linear_emission_estimate(n_ - 1, dt);
}

void FairingWindow::restore(Channel& ch, const Learnt& l) {
  ch.estimator.restore(l.estimates);
  ch.mu = l.mu;
  ch.level = l.level;
  ch.rest = l.rest;
  ch.check.state() = l.check;
  ch.candidate_level = l.candidate_level;
  ch.filling_moved = l.filling_moved;
}

void FairingWindow::slide(int count) {
  // Drop the oldest `count` samples (emitted long ago): O(1) on average (sliding_array.hpp).
  auto drop = [&](auto& v) { v.drop_front(static_cast<std::size_t>(count), static_cast<std::size_t>(n_)); };
  drop(samples_);
  drop(sampled_step_);
  drop(stamp_);
  drop(z_);
  drop(held_);
  drop(stand_in_);
  if (config_.solver == WindowSolver::Linear) {
    drop(zeta_);
    drop(residual_);
    drop(rest_zeta_);
    drop(c_);
    drop(dzp_);
    drop(cp_);
  } else {
    drop(x_);
    drop(y_);
    drop(window_clamped_);
  }
  if (positions_) {
    drop(zp_);
    drop(xp_);
    drop(yp_);
  }
  n_ -= count;
}

// An outlier (outlier_guard.hpp; alone, or up to kMaxHeldRun in a row) is held at the
// prediction: z and p, the values the window takes instead. A held sample that the next one shows
// to be a motion's start is taken back into the window as measured (only the newest held sample
// can be: the adaptation's copy is from just before it). step: how long after the window's
// newest sample s was taken (0: it starts a window).
bool FairingWindow::hold_outliers(const Sample& s, double step, Quat& z, Vec3& p, char& held) {
  using Verdict = OutlierGuard::Verdict;
  held = 0;
  // Not in a gyro-aided window: its residuals and bias estimate take each increment in for
  // good, so a release could not take a held one back.
  if (!rot_guard_.on() || aided_) return false;
  if (n_ == 0 || step <= 0.0) {
    rot_guard_.restart();
    pos_guard_.restart();
    return false;
  }
  const auto last = static_cast<std::size_t>(n_ - 1);
  const bool linear = config_.solver == WindowSolver::Linear;
  z = so3::aligned_to(s.orientation, z_[last]);
  Vec3 increment = so3::log(z_[last].conjugate() * z);
  known_increment_ = {z_[last], z, increment};
  const Verdict rotation = rot_guard_.check(step, increment);
  if (rotation == Verdict::Hold) z = (z_[last] * so3::exp(increment)).normalized();
  if (rotation == Verdict::Release) {
    z_[last] = so3::aligned_to(samples_[last].orientation, last > 0 ? z_[last - 1] : z_[last]);
    if (linear && last > 0) zeta_[last - 1] = so3::log(z_[last - 1].conjugate() * z_[last]);
    rest_chart_ready_ = false;  // its rest increments too, all of them at the next sample
  }
  p = s.position;
  Verdict position = Verdict::Take;
  if (positions_ && s.has_position()) {
    Vec3 dp = s.position - zp_[last];
    position = pos_guard_.check(step, dp);
    if (position == Verdict::Hold) p = zp_[last] + dp;
    if (position == Verdict::Release) {
      zp_[last] = samples_[last].position;
      if (linear && last > 0) dzp_[last - 1] = zp_[last] - zp_[last - 1];
    }
  }
  // Not yet emitted (a lag): a released channel is emitted as measured.
  if (rotation == Verdict::Release) held_[last] &= ~kHeldRotation;
  if (position == Verdict::Release) held_[last] &= ~kHeldPosition;
  if (rotation == Verdict::Release || position == Verdict::Release) {
    ++counters_.released;
    // The adaptation learns from the released sample as measured, as if it had never been held.
    if (linear && before_hold_dt_ >= 0.0) {
      restore(rot_, rot_before_hold_);
      restore(pos_, pos_before_hold_);
      linear_emission_estimate(n_ - 1 - config_.lag, before_hold_dt_);
    }
  }
  held = (rotation == Verdict::Hold ? kHeldRotation : 0) | (position == Verdict::Hold ? kHeldPosition : 0);
  return held != 0;
}

Vec3 FairingWindow::increment_log(const Quat& from, const Quat& to) const {
  const KnownIncrement& known = known_increment_;
  if (known.from.coeffs() == from.coeffs() && known.to.coeffs() == to.coeffs()) return known.log;
  return so3::log(from.conjugate() * to);
}

// Whether the window stands in for samples lost now: where each of its samples is one interval,
// the linear solver's (whose emitted rows know nothing of the samples' times) with its rate
// known and no continuity (a stand-in has no emitted pose to continue from), not gyro-aided (each
// step is integrated from its own readings), not repeating; not at rest, where a longer step
// moves nothing and a stand-in would only bend the rest test's statistics (its slope's noise is
// white noise's; a stand-in's is its neighbours'); and not while the stamps jitter
// (note_step_grid).
bool FairingWindow::stands_in() const {
  return config_.solver == WindowSolver::Linear && config_.continuity == 0.0 && prepared_ && rate_ > 0.0 && n_ > 0 &&
         !aided_ && !repeating_ && !(rot_.estimator.at_rest() && (!positions_ || pos_.estimator.at_rest())) &&
         !(last_time_ - off_grid_time_ < kOffGridMemory);
}

// A step off the grid of whole intervals (shorter than one, or between two whole numbers by more
// than kLostStepTolerance; or a clump's) says the stamps jitter: receive times, where a long step
// is as likely a late sample, with an early one after it, as a lost one. For kOffGridMemory after
// one, nothing is stood in for.
void FairingWindow::note_step_grid(double step) {
  if (!(rate_ > 0.0) || !(step > 0.0)) return;
  const double intervals = step * rate_;
  if (intervals < 1.0 - kLostStepTolerance || std::abs(intervals - std::round(intervals)) > kLostStepTolerance ||
      gate_.sampled_step() != step)
    off_grid_time_ = last_time_;
}

// How many samples the step from the window's newest sample lost: j − 1 for a step within
// kLostStepTolerance of j of the stream's intervals (2 ≤ j, at most kMaxLostInStep lost; the gate
// calls a longer step a gap), where the window stands in for them; not on a clump's step (the
// stamps do not give it).
int FairingWindow::lost_in_step(double step) const {
  if (!stands_in() || gate_.sampled_step() != step) return 0;
  const double intervals = step * rate_;
  const double j = std::round(intervals);
  if (j < 2.0 || j > kMaxLostInStep + 1 || std::abs(intervals - j) > kLostStepTolerance) return 0;
  return static_cast<int>(j) - 1;
}

// A sample lost before s, at fraction f of the step from the window's newest sample: on the
// geodesic (and the position's line) between the two, taken into the window and faired as its
// other samples, dt after the one before it. Emits what is due at the lag (never the stand-in).
int FairingWindow::stand_in(const Sample& s, double f, double dt, std::span<FairedPose> out) {
  const auto last = static_cast<std::size_t>(n_ - 1);
  Sample lost = s;
  lost.time = stamp_[last] + f * (s.time - stamp_[last]);
  lost.orientation = z_[last].slerp(f, so3::aligned_to(s.orientation, z_[last])).normalized();
  if (positions_) lost.position = zp_[last] + f * (s.position - zp_[last]);
  append(lost);
  ++counters_.lost;
  const auto i = static_cast<std::size_t>(n_ - 1);
  stand_in_[i] = 1;
  since_stand_in_ = 0;
  const int k = n_ - 1 - config_.lag;
  linear_emission_estimate(k, dt);
  if (k < 0 || stand_in_[static_cast<std::size_t>(k)]) return 0;
  out[0] = emit(k);
  return 1;
}

bool FairingWindow::gyro_aided(const Sample& s) const {
  // A non-finite reading is no reading: it would poison the window and the estimates.
  return config_.gyro.enabled && has_gyro_reading(s) && config_.solver == WindowSolver::Linear &&
         config_.horizon_s == 0.0;
}

void FairingWindow::append(const Sample& s) {
  if (n_ == 0) {
    positions_ = s.has_position();
    aided_ = gyro_aided(s);
    missing_gyro_run_ = 0;
    since_stand_in_ = kNoStandIn;
  }
  since_stand_in_ = std::min(since_stand_in_ + 1, kNoStandIn);
  if (aided_ && !gyro_aided(s)) {
    ++missing_gyro_run_;
    ++counters_.gyro_bridged;
  } else {
    missing_gyro_run_ = 0;
  }
  if (n_ == w_) slide(1);
  const auto k = static_cast<std::size_t>(n_);
  samples_[k] = s;
  samples_[k].time = s.time + sampled_offset_;
  stamp_[k] = s.time;
  sampled_step_[k] = gate_.sampled_step();
  window_clamped_[k] = 0;
  held_[k] = 0;
  stand_in_[k] = 0;
  Quat z = s.orientation;
  if (n_ == 0) {
    if (z.w() < 0.0) z.coeffs() = -z.coeffs();
  } else {
    z = so3::aligned_to(z, z_[k - 1]);
  }
  z_[k] = z;
  if (config_.solver == WindowSolver::Linear) {
    if (n_ >= 1) zeta_[k - 1] = increment_log(z_[k - 1], z);
    if (positions_) {
      zp_[k] = s.position;
      if (n_ >= 1) dzp_[k - 1] = s.position - zp_[k - 1];
    }
    ++n_;
    if (aided_ && n_ >= 2) {
      const auto n = static_cast<std::size_t>(n_);
      gyro_.update(std::span<const Sample>(samples_).first(n), std::span<const Vec3>(zeta_).first(n - 1),
                   std::span<Vec3>(residual_).first(n - 1));
    }
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
    linear_window();
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

// The whole window at once (a flush): every correction, at each channel's current μ.
void FairingWindow::linear_window() {
  const int n = n_;
  const int emitted = n - 1 - config_.lag;
  const bool continuity = config_.continuity > 0.0;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    est_[k] = continuity && i < emitted ? Vec3(config_.continuity * c_[k]) : Vec3::Zero();
    e_[k] = continuity && i < emitted ? Vec3(config_.continuity * cp_[k]) : Vec3::Zero();
  }
  if (!prepared_) {
    for (int i = 0; i < n; ++i) xp_[static_cast<std::size_t>(i)] = zp_[static_cast<std::size_t>(i)];
    return;  // the rate is not known yet: the measurements pass
  }
  EmissionTarget whole = target_spec_;
  whole.horizon = 0.0;
  builder_.solve_window(n, rot_.mu, whole, rotation_increments(), est_);
  if (positions_) {
    builder_.solve_window(n, pos_.mu, whole, dzp_, e_);
    for (int i = 0; i < n; ++i) xp_[static_cast<std::size_t>(i)] = zp_[static_cast<std::size_t>(i)] + e_[static_cast<std::size_t>(i)];
  }
}

// rhs -= μ (D^m)ᵀ D^{m-1} w1, where w1 (in w_, n-1 entries) is W¹ of the linearisation point:
// the gradient of μ‖W^m x‖² with W^m x = D^{m-1} W¹x and W¹ linear in the correction.
void FairingWindow::smoothness_gradient(std::span<const Vec3> w1) {
  const int n = n_, m = config_.order;
  if (w1.data() != w_scratch_.data()) std::copy(w1.begin(), w1.begin() + (n - 1), w_scratch_.begin());
  int len = n - 1;
  for (int p = 1; p < m; ++p) forward_difference_in_place(w_scratch_, len--);
  for (int p = 0; p < m; ++p) difference_adjoint_in_place(w_scratch_, len++);
  for (int i = 0; i < n; ++i) rhs_[static_cast<std::size_t>(i)] -= rot_.mu * w_scratch_[static_cast<std::size_t>(i)];
}

void FairingWindow::gauss_newton_rotation(const BandedCholesky& a) {
  const int n = n_;
  const int m = config_.order;
  const double mu = rot_.mu;
  const double kappa = config_.continuity;
  const int emitted = n - 1 - config_.lag;  // indices below this were emitted
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    Vec3 g = so3::log(z_[k].conjugate() * x_[k]);  // data residual
    if (kappa > 0.0 && i < emitted) g += kappa * so3::log(y_[k].conjugate() * x_[k]);
    rhs_[k] = -g;
  }
  if (n > m && mu > 0.0) {
    for (int j = 0; j + 1 < n; ++j) w_scratch_[static_cast<std::size_t>(j)] = so3::log(x_[static_cast<std::size_t>(j)].conjugate() * x_[static_cast<std::size_t>(j + 1)]);
    smoothness_gradient(w_scratch_);
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
