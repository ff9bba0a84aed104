#include "quality_configurations.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "posefair/core/exponential_slerp_filter.hpp"
#include "posefair/core/one_euro_filter.hpp"
#include "posefair/core/pose_prediction.hpp"

namespace posefair::tools {
namespace {

// A filter that passes each sample on as it comes, timed.
template <class Filter>
DeliveredStream run_filter(const PoseSequence& in, Filter f) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Quat> y(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) y[i] = f.filter(in.orientation[i], in.time[i]);
  const double ns = 1e9 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                    static_cast<double>(std::max<std::size_t>(1, in.size()));
  return delivered_as_sampled(in, std::move(y), ns);
}

// n values from lo to hi, evenly spaced in log, rounded to 3 significant digits so that the
// configuration text names them exactly.
std::vector<double> log_spaced(double lo, double hi, int n) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) {
    const double x = lo * std::pow(hi / lo, static_cast<double>(k) / (n - 1));
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", x);
    v.push_back(std::strtod(b, nullptr));
  }
  return v;
}

// The longest lag in whole samples at this rate that does not exceed lag_s (at least one
// sample when lag_s > 0): a lag variant is meant to fit its budget.
int lag_samples(double lag_s, double rate) {
  if (lag_s <= 0.0) return 0;
  return std::max(1, static_cast<int>(std::floor(lag_s * rate + 1e-9)));
}

}  // namespace

std::vector<SmoothingCandidate> smoothing_candidates(const QualityDataset& d, bool quick) {
  double rate = std::numeric_limits<double>::infinity();
  for (const QualitySequence& q : d.sequences) rate = std::min(rate, q.rate_hz);
  std::vector<SmoothingCandidate> out;
  char buf[200];
  out.push_back({"raw", "input", [](const QualitySequence& q) { return delivered_as_sampled(q.input, q.input.orientation, 0.0); }});
  // The engine exactly as a user who sets nothing gets it: whatever WindowConfig{}'s defaults are.
  out.push_back({"posefair-default", "WindowConfig{}", [](const QualitySequence& q) { return run_engine(q.input, WindowConfig{}); },
                 true});
  out.push_back({"one-euro-default", "mincutoff=1Hz beta=0 dcutoff=1Hz",
                 [](const QualitySequence& q) { return run_filter(q.input, QuatOneEuroFilter(1.0, 0.0, 1.0)); }});

  // posefair tuned: 80 configurations. m × (the adapted smoothing and 9 cutoffs, 0.25 Hz to 0.4
  // of the slowest rate) × {lag 0 with the default 0.5 s window, lag 0 with W = 32, lag ≤ 10 ms,
  // lag ≤ 30 ms}. Lags are whole samples (the most that fit the time, at least 1). μ is capped
  // at the engine's largest (kMaxSmoothing), which low cutoffs at 1 kHz reach. Gaps longer than
  // 2.5 periods restart the window (a fixed choice, not a tuned axis).
  const std::vector<double> cutoffs = log_spaced(0.25, 0.4 * rate, 9);
  struct Variant {
    int window;  // 0: the default time span
    double lag_s;
  };
  const Variant variants[] = {{0, 0.0}, {32, 0.0}, {0, 0.010}, {0, 0.030}};
  std::vector<double> smoothings = cutoffs;
  smoothings.insert(smoothings.begin(), 0.0);  // 0: adapted
  for (int m : {2, 3})
    for (double fc : smoothings)
      for (const Variant& v : variants) {
        char smoothing[40];
        if (fc > 0.0)
          std::snprintf(smoothing, sizeof smoothing, "cutoff=%gHz", fc);
        else
          std::snprintf(smoothing, sizeof smoothing, "adapted");
        if (v.lag_s > 0.0)
          std::snprintf(buf, sizeof buf, "m=%d %s lag<=%gms", m, smoothing, 1e3 * v.lag_s);
        else if (v.window > 0)
          std::snprintf(buf, sizeof buf, "m=%d %s W=%d lag=0", m, smoothing, v.window);
        else
          std::snprintf(buf, sizeof buf, "m=%d %s lag=0", m, smoothing);
        out.push_back({"posefair", buf, [m, fc, v](const QualitySequence& q) {
                         WindowConfig c;
                         c.order = m;
                         c.lag = lag_samples(v.lag_s, q.rate_hz);
                         c.window = v.window;
                         if (fc > 0.0) c.smoothing_r = std::min(kMaxSmoothing, smoothing_for_cutoff(fc, q.rate_hz, m));
                         c.rate_hz = q.rate_hz;
                         c.gate.gap_threshold = 2.5 / q.rate_hz;
                         return run_engine(q.input, c);
                       }});
      }

  // One Euro tuned: 80 configurations, mincutoff 0.25 … 1000 Hz (the top one lags 0.16 ms at
  // any rate, so every budget has a One Euro that fits) × 8 values of β, dcutoff 1 Hz.
  for (double minc : log_spaced(0.25, 1000.0, 10))
    for (double beta : {0.0, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0}) {
      std::snprintf(buf, sizeof buf, "mincutoff=%gHz beta=%g dcutoff=1Hz", minc, beta);
      out.push_back({"one-euro", buf, [minc, beta](const QualitySequence& q) {
                       return run_filter(q.input, QuatOneEuroFilter(minc, beta, 1.0));
                     }});
    }

  // Exponential slerp filter: 8 time constants.
  for (double tau_ms : {0.1, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0}) {
    std::snprintf(buf, sizeof buf, "tau=%gms", tau_ms);
    out.push_back({"slerp", buf, [tau_ms](const QualitySequence& q) {
                     return run_filter(q.input, ExponentialSlerpFilter::with_time_constant(1e-3 * tau_ms));
                   }});
  }

  if (d.kind != "synthetic") return out;
  // Solver tables (synthetic only), lag 0, W = 32: Gauss–Newton (2 iterations) at 5 cutoffs …
  const std::vector<double> gn_cutoffs = quick ? std::vector<double>{cutoffs[2], cutoffs[5]}
                                               : std::vector<double>{cutoffs[1], cutoffs[3], cutoffs[5], cutoffs[7], cutoffs[8]};
  for (int m : {2, 3})
    for (double fc : gn_cutoffs) {
      std::snprintf(buf, sizeof buf, "m=%d cutoff=%gHz W=32 lag=0ms iterations=2", m, fc);
      out.push_back({"posefair-gn", buf, [m, fc](const QualitySequence& q) {
                       WindowConfig c;
                       c.order = m;
                       c.solver = WindowSolver::GaussNewton;
                       c.window = 32;
                       c.iterations = 2;
                       c.smoothing_r = std::min(kMaxSmoothing, smoothing_for_cutoff(fc, q.rate_hz, m));
                       c.gate.gap_threshold = 2.5 / q.rate_hz;
                       return run_engine(q.input, c);
                     }});
    }
  // … the paper's damped operators, K = 4 sweeps per sample, W = 16, anchored by the window
  // bound (dist on S³) or unbounded …
  for (int m : {2, 3})
    for (double lr : {0.1, 0.3})
      for (double eps : {0.01, std::numeric_limits<double>::infinity()}) {
        if (quick && lr == 0.1) continue;
        std::snprintf(buf, sizeof buf, "m=%d W=16 K=4 lambda_r=%g eps_r=%g bound=%s lag=0ms", m, lr, eps,
                      std::isfinite(eps) ? "window" : "none");
        out.push_back({"posefair-sweeps", buf, [m, lr, eps](const QualitySequence& q) {
                         WindowConfig c;
                         c.order = m;
                         c.window = 16;
                         c.solver = WindowSolver::DampedSweeps;
                         c.iterations = 4;
                         c.lambda_r = lr;
                         c.epsilon_r = eps;
                         c.bound = std::isfinite(eps) ? BoundPolicy::Window : BoundPolicy::Sample;
                         c.gate.gap_threshold = 2.5 / q.rate_hz;
                         return run_engine(q.input, c);
                       }});
      }
  // … and the ε promise per emitted sample or per window, at a bound tight enough to bite
  // (half the noise bound), m = 2, W = 32, cutoff 4 Hz.
  const double noise = d.name.find("noise0.01") != std::string::npos ? 0.01 : 0.05;
  for (WindowSolver solver : {WindowSolver::Linear, WindowSolver::GaussNewton})
    for (BoundPolicy bound : {BoundPolicy::Sample, BoundPolicy::Window}) {
      if (solver == WindowSolver::Linear && bound == BoundPolicy::Window) continue;  // needs an iterative solver
      std::snprintf(buf, sizeof buf, "%s bound=%s eps_r=%g m=2 W=32 cutoff=4Hz lag=0ms",
                    solver == WindowSolver::Linear ? "linear" : "gauss-newton", bound == BoundPolicy::Sample ? "sample" : "window",
                    0.5 * noise);
      out.push_back({"posefair-bound", buf, [solver, bound, noise](const QualitySequence& q) {
                       WindowConfig c;
                       c.order = 2;
                       c.window = 32;
                       c.solver = solver;
                       c.iterations = 2;
                       c.smoothing_r = smoothing_for_cutoff(4.0, q.rate_hz, 2);
                       c.epsilon_r = 0.5 * noise;
                       c.bound = bound;
                       return run_engine(q.input, c);
                     }});
    }
  return out;
}

std::vector<PredictionCandidate> prediction_candidates() {
  std::vector<PredictionCandidate> out;
  using Horizons = std::vector<double>;
  using Out = std::vector<std::vector<Quat>>;
  // Runs a predictor with push()/predict(h) over a sequence for every horizon.
  const auto drive = [](auto predictor, const QualitySequence& q, const Horizons& hs) {
    Out y(hs.size(), std::vector<Quat>(q.input.size()));
    for (std::size_t i = 0; i < q.input.size(); ++i) {
      predictor.push(q.input.orientation[i], q.input.time[i]);
      for (std::size_t k = 0; k < hs.size(); ++k) y[k][i] = predictor.predict(hs[k]);
    }
    return y;
  };
  out.push_back({"hold", "newest sample", [](const QualitySequence& q, const Horizons& hs) {
                   return Out(hs.size(), q.input.orientation);
                 }});
  out.push_back({"dead-reckoning", "velocity from the last two samples",
                 [drive](const QualitySequence& q, const Horizons& hs) { return drive(DeadReckoningPredictor(), q, hs); }});
  out.push_back({"slerp-extrapolation", "slerp(1 + h/period) of the last two samples",
                 [drive](const QualitySequence& q, const Horizons& hs) {
                   return drive(SlerpExtrapolationPredictor(1.0 / q.rate_hz), q, hs);
                 }});
  out.push_back({"one-euro-dr-default", "mincutoff=1Hz beta=0 dcutoff=1Hz", [drive](const QualitySequence& q, const Horizons& hs) {
                   return drive(OneEuroDeadReckoningPredictor(1.0, 0.0, 1.0), q, hs);
                 }});
  // One Euro + dead reckoning tuned: 80 configurations; for prediction the derivative's own
  // cutoff matters, so it is an axis here.
  char buf[160];
  for (double minc : {1.0, 4.0, 16.0, 64.0, 1000.0})
    for (double beta : {0.0, 0.1, 1.0, 10.0})
      for (double dc : {1.0, 4.0, 16.0, 64.0}) {
        std::snprintf(buf, sizeof buf, "mincutoff=%gHz beta=%g dcutoff=%gHz", minc, beta, dc);
        out.push_back({"one-euro-dr", buf, [drive, minc, beta, dc](const QualitySequence& q, const Horizons& hs) {
                         return drive(OneEuroDeadReckoningPredictor(minc, beta, dc), q, hs);
                       }});
      }
  return out;
}

EnginePrediction predict_with_engine(const QualitySequence& q, double horizon_s) {
  WindowConfig c;
  c.horizon_s = horizon_s;
  DeliveredStream s = run_engine(q.input, c);
  const double diff = difference_to_fair_causal(q.input, c, s);
  if (diff > 1e-9)
    throw std::runtime_error("run_engine and fair_causal differ by " + std::to_string(diff) + " rad with horizon_s set");
  EnginePrediction p;
  double delay = 0.0;
  for (std::size_t i = 0; i < s.pose.size(); ++i) {
    if (std::abs(s.stamp[i] - (q.input.time[i] + horizon_s)) > 1e-9) p.stamped_ahead = false;
    delay += s.delivered[i] - q.input.time[i];
  }
  p.delivery_ms = s.pose.empty() ? 0.0 : 1e3 * delay / static_cast<double>(s.pose.size());
  p.pose = std::move(s.pose);
  return p;
}

}  // namespace posefair::tools
