#include <CLI/CLI.hpp>

#include "bench_command.hpp"
#include "bench_latency_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>

#include "benchmark_data.hpp"
#include "posefair/core/error.hpp"
#include "posefair/core/causal_fairing.hpp"
#include "posefair/core/exponential_slerp_filter.hpp"
#include "posefair/core/fairing_window.hpp"
#include "posefair/core/one_euro_filter.hpp"
#include "posefair/core/quality_metrics.hpp"
#include "quality_datasets.hpp"

namespace posefair::tools {
namespace {

struct Candidate {
  std::string family;  // "posefair", "posefair-gn", "posefair-sweeps", "one-euro", "slerp"
  std::string config;
  std::function<std::vector<Quat>(const PoseSequence&)> run;
  // A lagged engine emits sample i's pose L samples later, stamped with sample i's time: that
  // delivery delay is added to the lag measured from the timestamps.
  double delivery_delay_s = 0.0;
};

struct Result {
  std::string dataset, family, config;
  double error = 0.0;      // rad (truth) or rad/s (BROAD: angular rate against the gyroscope)
  double max_error = 0.0;
  double jitter = 0.0;     // rad/s²
  double lag_ms = 0.0;
  double max_deviation = 0.0;  // rad, physical angle from the input
  double ns_per_sample = 0.0;
};

std::vector<Quat> run_window(const PoseSequence& in, const WindowConfig& c) {
  return fair_causal(in, c).poses.orientation;
}

std::vector<Candidate> candidates(const QualityDataset& d, bool quick) {
  std::vector<Candidate> out;
  const double rate = d.rate_hz;
  char buf[200];
  // Lags: none, about 10 ms and about 30 ms (in samples at this rate, at least 0 and 1).
  std::vector<int> lags{0};
  for (double ms : {10.0, 30.0}) {
    const int l = std::max(1, static_cast<int>(std::lround(ms * 1e-3 * rate)));
    if (l != lags.back()) lags.push_back(l);
  }
  std::vector<double> cutoffs;
  for (double fc : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0})
    if (fc < 0.45 * rate) cutoffs.push_back(fc);
  const std::vector<int> windows = quick ? std::vector<int>{16, 32} : std::vector<int>{8, 16, 32, 64};
  for (int m : {2, 3})
    for (int w : windows)
      for (double fc : cutoffs)
        for (int lag : lags)
          for (double kappa : {0.0, 0.5, 2.0, 8.0}) {
            if (lag >= w || w < m + 1 || smoothing_for_cutoff(fc, rate, m) > kMaxSmoothing) continue;
            WindowConfig c;
            c.order = m;
            c.window = w;
            c.lag = lag;
            c.smoothing_r = smoothing_for_cutoff(fc, rate, m);
            c.continuity = kappa;
            c.gate.gap_threshold = 2.5 / rate;
            std::snprintf(buf, sizeof buf, "m=%d W=%d cutoff=%gHz lag=%d kappa=%g", m, w, fc, lag, kappa);
            try {
              FairingWindow probe(c);  // refuses unstable continuity settings
            } catch (const std::invalid_argument&) {
              continue;
            }
            out.push_back({"posefair", buf, [c](const PoseSequence& in) { return run_window(in, c); }, lag / rate});
          }
  // The exact relinearised solve, for comparison with the linear one.
  for (int m : {2, 3})
    for (double fc : cutoffs) {
      if (smoothing_for_cutoff(fc, rate, m) > kMaxSmoothing) continue;
      WindowConfig c;
      c.order = m;
      c.window = 32;
      c.solver = WindowSolver::GaussNewton;
      c.iterations = 2;
      c.smoothing_r = smoothing_for_cutoff(fc, rate, m);
      c.gate.gap_threshold = 2.5 / rate;
      std::snprintf(buf, sizeof buf, "m=%d W=32 cutoff=%gHz lag=0 iterations=2", m, fc);
      out.push_back({"posefair-gn", buf, [c](const PoseSequence& in) { return run_window(in, c); }});
    }
  // The ε promise enforced per emitted sample or on the whole window after every iteration, at
  // a bound tight enough to bite (half the noise bound): how much does each policy cost?
  if (d.kind == "synthetic") {
    const double noise = d.name.find("noise0.01") != std::string::npos ? 0.01 : 0.05;
    for (WindowSolver solver : {WindowSolver::Linear, WindowSolver::GaussNewton})
      for (BoundPolicy bound : {BoundPolicy::Sample, BoundPolicy::Window}) {
        if (solver == WindowSolver::Linear && bound == BoundPolicy::Window) continue;
        WindowConfig c;
        c.order = 2;
        c.window = 32;
        c.solver = solver;
        c.iterations = 2;
        c.smoothing_r = smoothing_for_cutoff(std::min(4.0, 0.4 * rate), rate, 2);
        c.epsilon_r = 0.5 * noise;
        c.bound = bound;
        std::snprintf(buf, sizeof buf, "%s bound=%s eps_r=%g m=2 W=32 cutoff=4Hz lag=0",
                      solver == WindowSolver::Linear ? "linear" : "gauss-newton", bound == BoundPolicy::Sample ? "sample" : "window",
                      c.epsilon_r);
        out.push_back({"posefair-bound", buf, [c](const PoseSequence& in) { return run_window(in, c); }});
      }
  }
  // The paper's damped operators, K sweeps per sample. Their only anchor to the data is the
  // bound (Fig. 1), so they run with the window bound at a few ε (dist on S³).
  for (int m : {2, 3})
    for (int w : {16, 32})
      for (double lr : {0.1, 0.3})
        for (double eps : {0.003, 0.01, 0.03, std::numeric_limits<double>::infinity()}) {
        if (quick && (w == 32 || eps < 0.01)) continue;
        WindowConfig c;
        c.order = m;
        c.window = w;
        c.solver = WindowSolver::DampedSweeps;
        c.iterations = 4;
        c.lambda_r = lr;
        c.epsilon_r = eps;
        c.bound = std::isfinite(eps) ? BoundPolicy::Window : BoundPolicy::Sample;
        c.gate.gap_threshold = 2.5 / rate;
        std::snprintf(buf, sizeof buf, "m=%d W=%d K=4 lambda_r=%g eps_r=%g bound=%s lag=0", m, w, lr, eps,
                      std::isfinite(eps) ? "window" : "none");
        out.push_back({"posefair-sweeps", buf, [c](const PoseSequence& in) { return run_window(in, c); }});
      }
  // One Euro, tuned by grid search per data set.
  for (double minc : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0})
    for (double beta : {0.0, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0}) {
      std::snprintf(buf, sizeof buf, "mincutoff=%gHz beta=%g dcutoff=1Hz", minc, beta);
      out.push_back({"one-euro", buf, [minc, beta](const PoseSequence& in) {
                       QuatOneEuroFilter f(minc, beta, 1.0);
                       std::vector<Quat> y(in.size());
                       for (std::size_t i = 0; i < in.size(); ++i) y[i] = f.filter(in.orientation[i], in.time[i]);
                       return y;
                     }});
    }
  for (double alpha : {0.05, 0.1, 0.2, 0.3, 0.5, 0.7}) {
    std::snprintf(buf, sizeof buf, "alpha=%g", alpha);
    out.push_back({"slerp", buf, [alpha](const PoseSequence& in) {
                     auto f = ExponentialSlerpFilter::with_alpha(alpha);
                     std::vector<Quat> y(in.size());
                     for (std::size_t i = 0; i < in.size(); ++i) y[i] = f.filter(in.orientation[i], in.time[i]);
                     return y;
                   }});
  }
  return out;
}

// BROAD: the shift between the raw optical rates and the gyroscope, a property of the recording
// (clock offset and sensor latency), measured once; a smoother's lag is measured against it.
double raw_rate_shift(const QualityDataset& d) {
  const auto rates = body_rates(d.input.orientation, d.input.time);
  return best_rate_shift(rates, d.input.time, d.gyro, d.use, -0.05, 0.05, 0.25 / d.rate_hz).shift;
}

Result score(const QualityDataset& d, const Candidate& c, double raw_shift) {
  Result r;
  r.dataset = d.name;
  r.family = c.family;
  r.config = c.config;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Quat> y = c.run(d.input);
  r.ns_per_sample = 1e9 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                    static_cast<double>(d.input.size());
  const double dt = 1.0 / d.rate_hz;
  r.jitter = jitter(y, dt, d.use);
  for (std::size_t i = 0; i < y.size(); ++i)
    r.max_deviation = std::max(r.max_deviation, so3::rotation_angle(y[i], d.input.orientation[i]));
  if (d.kind == "broad") {
    const auto rates = body_rates(y, d.input.time);
    r.error = rate_error(rates, d.input.time, d.gyro, raw_shift, d.use);
    const ShiftFit fit = best_rate_shift(rates, d.input.time, d.gyro, d.use, raw_shift - 0.06, raw_shift + 0.01, 0.25 * dt);
    r.lag_ms = 1e3 * (raw_shift - fit.shift + c.delivery_delay_s);
    r.max_error = std::numeric_limits<double>::quiet_NaN();
  } else {
    const ErrorStats e = rotation_error(y, d.truth, d.use);
    r.error = e.rms;
    r.max_error = e.max;
    r.lag_ms = 1e3 * (lag_to_truth(y, d.truth, dt, static_cast<int>(std::ceil(0.06 * d.rate_hz)) + 1, d.use) + c.delivery_delay_s);
  }
  return r;
}

const Result* best(const std::vector<Result>& rs, const std::string& dataset, const std::string& family, double budget_ms,
                   double slack_ms) {
  const Result* b = nullptr;
  for (const Result& r : rs)
    if (r.dataset == dataset && r.family == family && std::isfinite(r.error) && r.lag_ms <= budget_ms + slack_ms &&
        (!b || r.error < b->error))
      b = &r;
  return b;
}

int bench_quality(const std::string& data_dir, const std::string& out_dir, bool quick) {
  std::vector<QualityDataset> sets;
  try {
    sets = load_quality_datasets(data_dir, quick, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "posefair bench quality: " << e.what() << "\n";
    return exit_code(ErrorKind::NoInput);
  }
  std::filesystem::create_directories(out_dir);
  std::vector<Result> results;
  for (const QualityDataset& d : sets) {
    const double raw_shift = d.kind == "broad" ? raw_rate_shift(d) : 0.0;
    Candidate raw{"raw", "input", [](const PoseSequence& in) { return in.orientation; }};
    results.push_back(score(d, raw, raw_shift));
    const auto cs = candidates(d, quick);
    for (const Candidate& c : cs) results.push_back(score(d, c, raw_shift));
    std::fprintf(stderr, "%-36s %6zu samples at %7.1f Hz, %zu configurations%s\n", d.name.c_str(), d.input.size(), d.rate_hz,
                 cs.size(), d.kind == "broad" ? (", raw optical-to-gyro shift " + std::to_string(1e3 * raw_shift) + " ms").c_str() : "");
  }
  const std::string runs_path = out_dir + "/quality-runs.csv";
  std::ofstream runs(runs_path);
  runs << "dataset,family,config,error,max_error,jitter,lag_ms,max_deviation,ns_per_sample\n";
  for (const Result& r : results)
    runs << r.dataset << ',' << r.family << ",\"" << r.config << "\"," << r.error << ',' << r.max_error << ',' << r.jitter << ','
         << r.lag_ms << ',' << r.max_deviation << ',' << r.ns_per_sample << '\n';

  // For each lag budget: the most accurate configuration of each family whose measured lag fits.
  const std::string summary_path = out_dir + "/quality-summary.csv";
  std::ofstream summary(summary_path);
  summary << "dataset,budget_ms,family,config,error,jitter,lag_ms,ns_per_sample\n";
  std::printf("| data set | lag budget | posefair error / jitter / lag | One Euro error / jitter / lag | lower error | lower jitter |\n");
  std::printf("|---|---|---|---|---|---|\n");
  int wins = 0, comparisons = 0;
  for (const QualityDataset& d : sets) {
    const double slack = 0.5e3 / d.rate_hz;
    for (double budget : {0.0, 10.0, 30.0}) {
      const Result* p = best(results, d.name, "posefair", budget, slack);
      const Result* o = best(results, d.name, "one-euro", budget, slack);
      for (const Result* r : {p, o})
        if (r)
          summary << d.name << ',' << budget << ',' << r->family << ",\"" << r->config << "\"," << r->error << ',' << r->jitter << ','
                  << r->lag_ms << ',' << r->ns_per_sample << '\n';
      auto cell = [](const Result* r) {
        char b[160];
        if (!r) return std::string("none fits");
        std::snprintf(b, sizeof b, "%.4g / %.4g / %.1f ms", r->error, r->jitter, r->lag_ms);
        return std::string(b);
      };
      const bool lower_error = p && (!o || p->error < o->error);
      const bool lower_jitter = p && (!o || p->jitter < o->jitter);
      ++comparisons;
      if (lower_error && lower_jitter) ++wins;
      std::printf("| %s | %g ms | %s | %s | %s | %s |\n", d.name.c_str(), budget, cell(p).c_str(), cell(o).c_str(),
                  lower_error ? "posefair" : "One Euro", lower_jitter ? "posefair" : "One Euro");
    }
  }
  std::printf("\nposefair lower in both error and jitter in %d of %d comparisons\n", wins, comparisons);
  std::printf("wrote %s and %s\n", runs_path.c_str(), summary_path.c_str());
  return kExitOk;
}

}  // namespace

void add_bench_command(CLI::App& app, int& exit_code) {
  auto* bench = app.add_subcommand("bench", "Measure posefair against reference filters");
  bench->require_subcommand(1);
  auto* quality = bench->add_subcommand("quality", "Accuracy, jitter and lag on synthetic and recorded data");
  auto data = std::make_shared<std::string>(benchmark_data_dir().string());  // $POSEFAIR_DATA or ../shared/data
  auto out = std::make_shared<std::string>("build/bench-quality");
  auto quick = std::make_shared<bool>(false);
  quality->add_option("--data", *data, "folder with the recorded data sets (tum/, broad/, bvh/); default $POSEFAIR_DATA, else ../shared/data")->capture_default_str();
  quality->add_option("-o,--output", *out, "folder for quality-runs.csv and quality-summary.csv")->capture_default_str();
  quality->add_flag("--quick", *quick, "synthetic data only, fewer configurations (seconds, for tests)");
  quality->callback([=, &exit_code] { exit_code = bench_quality(*data, *out, *quick); });
  add_bench_latency_command(*bench, exit_code);
}

}  // namespace posefair::tools
