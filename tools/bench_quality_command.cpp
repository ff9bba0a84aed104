#include <CLI/CLI.hpp>

#include "bench_command.hpp"
#include "bench_fusion_command.hpp"
#include "bench_gyro_fairing_command.hpp"
#include "bench_latency_command.hpp"
#include "bench_streams_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "benchmark_data.hpp"
#include "posefair/core/error.hpp"
#include "quality_configurations.hpp"
#include "quality_datasets.hpp"
#include "quality_scoring.hpp"
#include "quality_tuning.hpp"

namespace posefair::tools {
namespace {

constexpr double kHorizonsMs[] = {10.0, 20.0, 30.0};

std::string row_name(const std::string& family) {
  if (family == "posefair-default") return "posefair default";
  if (family == "posefair") return "posefair tuned";
  if (family == "one-euro-default") return "One Euro default";
  if (family == "one-euro") return "One Euro tuned";
  if (family == "slerp") return "slerp tuned";
  if (family == "posefair-gn") return "Gauss–Newton tuned";
  if (family == "posefair-sweeps") return "paper's sweeps tuned";
  if (family == "hold") return "hold (no prediction)";
  if (family == "dead-reckoning") return "dead reckoning";
  if (family == "slerp-extrapolation") return "slerp extrapolation";
  if (family == "one-euro-dr-default") return "One Euro default + DR";
  if (family == "one-euro-dr") return "One Euro tuned + DR";
  return family;
}

std::string role(const QualityDataset& d, std::size_t s) {
  bool train = false, report = false;
  for (const QualityFold& f : d.folds) {
    train = train || std::find(f.train.begin(), f.train.end(), s) != f.train.end();
    report = report || std::find(f.report.begin(), f.report.end(), s) != f.report.end();
  }
  return train && report ? "train+report" : train ? "train" : report ? "report" : "unused";
}

// ---------------------------------------------------------------------------------------------
// Smoothing

struct SmoothingRuns {
  const QualityDataset* d = nullptr;
  std::vector<SmoothingCandidate> cands;
  std::vector<std::vector<SmoothingScore>> score;  // [candidate][sequence]
  std::size_t index(const std::string& family) const {
    for (std::size_t c = 0; c < cands.size(); ++c)
      if (cands[c].family == family) return c;
    return cands.size();
  }
};

double rule_error(const SmoothingScore& s, const SelectionRule& rule) { return rule.delivered ? s.error_delivered : s.error_aligned; }
bool rule_fits(const SmoothingScore& s, const SelectionRule& rule) {
  return rule.delivered || s.lag_ms <= rule.budget_ms + kBudgetSlackMs;
}

// The configuration of a tuned family chosen on a fold's training sequences.
std::optional<std::size_t> chosen(const SmoothingRuns& r, const std::string& family, const SelectionRule& rule, const QualityFold& f) {
  std::vector<std::size_t> members;
  for (std::size_t c = 0; c < r.cands.size(); ++c)
    if (r.cands[c].family == family) members.push_back(c);
  const std::size_t raw = r.index("raw");
  return pick_on_training(
      members, f.train,
      [&](std::size_t c, std::size_t s) { return rule_error(r.score[c][s], rule) / rule_error(r.score[raw][s], rule); },
      [&](std::size_t c, std::size_t s) { return r.score[c][s].lag_ms; },
      rule.delivered ? std::numeric_limits<double>::infinity() : rule.budget_ms + kBudgetSlackMs);
}

struct Row {
  std::string name;
  std::string family;
  std::vector<std::string> configs;  // per fold
  Spread error_a, error_b, lag, delivery, jitter, relative, ns;
  std::size_t over_budget = 0;  // report sequences whose lag (b) exceeds the budget
  bool found = false;
};

// One row over every fold's report sequences: the fixed candidate `fixed`, or the family's
// configuration chosen per fold under `rule`.
Row make_row(const SmoothingRuns& r, const std::string& family, std::optional<std::size_t> fixed, const SelectionRule& rule) {
  Row row;
  row.family = family;
  row.name = row_name(family);
  row.found = true;
  for (const QualityFold& f : r.d->folds) {
    const std::optional<std::size_t> c = fixed ? fixed : chosen(r, family, rule, f);
    if (!c) {
      row.found = false;
      row.configs.push_back("none fits");
      continue;
    }
    row.configs.push_back(r.cands[*c].config);
    for (std::size_t s : f.report) {
      const SmoothingScore& x = r.score[*c][s];
      row.error_a.add(x.error_delivered);
      row.error_b.add(x.error_aligned);
      row.lag.add(x.lag_ms);
      row.delivery.add(x.delivery_ms);
      row.jitter.add(x.jitter);
      row.relative.add(x.relative_error);
      row.ns.add(x.ns_per_sample);
      if (!rule_fits(x, rule)) ++row.over_budget;
    }
  }
  for (Spread* s : {&row.error_a, &row.error_b, &row.lag, &row.delivery, &row.jitter, &row.relative, &row.ns}) s->finish();
  std::sort(row.configs.begin(), row.configs.end());
  row.configs.erase(std::unique(row.configs.begin(), row.configs.end()), row.configs.end());
  return row;
}

Row fixed_row(const SmoothingRuns& r, const std::string& family, const SelectionRule& rule) {
  return make_row(r, family, r.index(family), rule);
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : "; ") + x;
  return s;
}

std::string fmt(double x, const char* f = "%.4g") {
  char b[48];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

void print_row(const Row& row, const char* selected) {
  std::printf("| %s | %s | %s | %s | %s | %s | %s |\n", row.name.c_str(), selected, format_spread(row.error_a).c_str(),
              format_spread(row.error_b).c_str(), format_spread(row.lag).c_str(), format_spread(row.jitter).c_str(),
              joined(row.configs).c_str());
}

void write_summary(std::ofstream& out, const std::string& dataset, const char* rule, const Row& row) {
  out << dataset << ',' << rule << ',' << row.family << ",\"" << joined(row.configs) << "\"," << row.error_a.count;
  for (const Spread* s : {&row.error_a, &row.error_b, &row.lag, &row.jitter, &row.relative})
    out << ',' << s->mean << ',' << s->min << ',' << s->max;
  out << ',' << row.delivery.mean << ',' << row.over_budget << ',' << row.ns.mean << '\n';
}

SmoothingRuns run_smoothing(const QualityDataset& d, bool quick, std::ofstream& runs) {
  SmoothingRuns r;
  r.d = &d;
  r.cands = smoothing_candidates(d, quick);
  r.score.assign(r.cands.size(), std::vector<SmoothingScore>(d.sequences.size()));
  for (std::size_t s = 0; s < d.sequences.size(); ++s) {
    const QualitySequence& q = d.sequences[s];
    // Every lag is measured from the raw stream's own best alignment on the same sequence (0 in
    // truth for synthetic and BVH, and by construction for TUM and BROAD), which takes the lag
    // estimate's own error on that sequence out of every row alike.
    double raw_shift_ms = 0.0;
    for (std::size_t c = 0; c < r.cands.size(); ++c) {
      const DeliveredStream out = r.cands[c].run(q);
      if (r.cands[c].default_engine) {
        const double diff = difference_to_fair_causal(q.input, WindowConfig{}, out);
        if (diff > 1e-9) throw std::runtime_error("run_engine and fair_causal differ by " + std::to_string(diff) + " rad");
      }
      SmoothingScore x = score_smoothing(q, d.kind == "broad", out);
      if (r.cands[c].family == "raw") raw_shift_ms = x.lag_ms;
      x.lag_ms -= raw_shift_ms;
      r.score[c][s] = x;
      runs << d.name << ',' << q.name << ',' << role(d, s) << ',' << r.cands[c].family << ",\"" << r.cands[c].config << "\","
           << x.error_delivered << ',' << x.error_aligned << ',' << x.lag_ms << ',' << raw_shift_ms << ',' << x.delivery_ms << ','
           << x.jitter << ',' << x.relative_error << ',' << x.max_deviation << ',' << x.ns_per_sample << '\n';
    }
  }
  return r;
}

// A comparison cell "error / jitter / lag" and the verdict of a row against One Euro tuned.
std::string cell(const Row& row, const SelectionRule& rule) {
  if (!row.found) return "none fits";
  return fmt(rule.delivered ? row.error_a.mean : row.error_b.mean) + " / " + fmt(row.jitter.mean) + " / " +
         fmt(row.lag.mean, "%.1f") + " ms";
}

std::string verdict(const Row& row, const Row& rival, const SelectionRule& rule, bool& wins) {
  wins = false;
  if (!row.found) return "no row";
  if (!rival.found) return "uncontested";
  if (!rule.delivered && row.lag.mean > rule.budget_ms + kBudgetSlackMs) return "no: lag over budget";
  const double e = rule.delivered ? row.error_a.mean : row.error_b.mean;
  const double re = rule.delivered ? rival.error_a.mean : rival.error_b.mean;
  std::string why;
  if (!(e < re)) why += "error +" + fmt(100.0 * (e / re - 1.0), "%.1f") + "%";
  if (!(row.jitter.mean < rival.jitter.mean))
    why += (why.empty() ? "" : ", ") + std::string("jitter +") + fmt(100.0 * (row.jitter.mean / rival.jitter.mean - 1.0), "%.1f") + "%";
  wins = why.empty();
  return wins ? "yes" : "no: " + why;
}

void print_smoothing(const std::vector<SmoothingRuns>& all, std::ofstream& summary, std::vector<std::string>& losses) {
  std::printf("## Smoothing: every row scored on the report split\n\n");
  std::printf("Each cell: mean over the report sequences (min–max). error (a): at the delivery time; error (b): at the\n"
              "best time alignment, whose shift is the lag (b) (alignment shift + delivery delay). Units: rad, BROAD\n"
              "rad/s against the gyroscope; jitter rad/s². Tuned rows: chosen on the training split, by the lowest\n"
              "error (b) whose mean lag there is within the budget (+%g ms), or by the lowest error (a) (\"delivered\").\n\n",
              kBudgetSlackMs);
  const SelectionRule& any = kSelectionRules[3];
  for (const SmoothingRuns& r : all) {
    const QualityDataset& d = *r.d;
    std::size_t reports = 0;
    for (const QualityFold& f : d.folds) reports += f.report.size();
    std::printf("### %s\n%s; %zu report sequences, %.4g Hz.", d.name.c_str(), d.split.c_str(), reports, d.sequences[0].rate_hz);
    if (d.kind == "tum") {
      std::printf(" The estimate's clock trails motion capture's by");
      for (const QualitySequence& q : d.sequences) std::printf(" %.1f ms (%s)", 1e3 * q.truth_shift, q.name.c_str());
      std::printf(", measured on the raw estimate; the truth is shifted by it.");
    }
    if (d.kind == "broad") {
      Spread shift;
      for (const QualitySequence& q : d.sequences) shift.add(1e3 * q.gyro_shift);
      shift.finish();
      std::printf(" Optical-to-gyroscope shift of the raw stream: %s ms.", format_spread(shift).c_str());
    }
    std::printf("\n\n");
    std::printf("| row | selected on | error (a) | error (b) | lag (b) ms | jitter | configuration |\n|---|---|---|---|---|---|---|\n");
    for (const char* fam : {"raw", "posefair-default", "one-euro-default"}) {
      const Row row = fixed_row(r, fam, any);
      print_row(row, "fixed");
      write_summary(summary, d.name, "fixed", row);
    }
    for (const SelectionRule& rule : kSelectionRules)
      for (const char* fam : {"posefair", "one-euro", "slerp"}) {
        const Row row = make_row(r, fam, std::nullopt, rule);
        print_row(row, rule.name);
        write_summary(summary, d.name, rule.name, row);
      }
    std::printf("\n");
  }
  std::printf("### posefair against One Euro tuned on the training split\n\n");
  std::printf("Cells: error / jitter / lag (b), means over the report sequences; error (b) for the budgets, (a) for\n"
              "\"delivered\". A row wins when its error and its jitter are both lower and its lag fits the budget.\n\n");
  std::printf("| data set | budget | posefair default | posefair tuned | One Euro tuned | default wins | tuned wins |\n"
              "|---|---|---|---|---|---|---|\n");
  int default_wins = 0, tuned_wins = 0, comparisons = 0;
  for (const SmoothingRuns& r : all)
    for (const SelectionRule& rule : kSelectionRules) {
      const Row def = fixed_row(r, "posefair-default", rule);
      const Row tuned = make_row(r, "posefair", std::nullopt, rule);
      const Row oe = make_row(r, "one-euro", std::nullopt, rule);
      bool dw = false, tw = false;
      const std::string dv = verdict(def, oe, rule, dw), tv = verdict(tuned, oe, rule, tw);
      default_wins += dw;
      tuned_wins += tw;
      ++comparisons;
      if (!dw) losses.push_back("smoothing, " + r.d->name + ", " + rule.name + ": posefair default " + cell(def, rule) +
                                " against One Euro tuned " + cell(oe, rule) + " (" + dv + ")");
      std::printf("| %s | %s | %s | %s | %s | %s | %s |\n", r.d->name.c_str(), rule.name, cell(def, rule).c_str(),
                  cell(tuned, rule).c_str(), cell(oe, rule).c_str(), dv.c_str(), tv.c_str());
    }
  std::printf("\nposefair default beats One Euro tuned in %d of %d comparisons; posefair tuned in %d of %d.\n\n", default_wins,
              comparisons, tuned_wins, comparisons);
}

void print_low_rate(const std::vector<SmoothingRuns>& all, std::vector<std::string>& losses) {
  bool any = false;
  for (const SmoothingRuns& r : all) any = any || r.d->kind == "tum";
  if (!any) return;
  std::printf("## Low-rate SLAM estimates (TUM): absolute and relative orientation error against raw\n\n");
  std::printf("Per report sequence: absolute = error (a), at the delivery time; relative = RMS error of the rotation\n"
              "between consecutive deliveries (rad). Tuned rows chosen on the other set by error (a). Percentages\n"
              "against raw.\n\n");
  std::printf("| data set | sequence | raw abs / rel | posefair default abs / rel | posefair tuned abs / rel | One Euro default abs / rel | One Euro tuned abs / rel |\n"
              "|---|---|---|---|---|---|---|\n");
  const SelectionRule& rule = kSelectionRules[3];
  for (const SmoothingRuns& r : all) {
    if (r.d->kind != "tum") continue;
    for (const QualityFold& f : r.d->folds)
      for (std::size_t s : f.report) {
        const auto& raw = r.score[r.index("raw")][s];
        const auto pct = [&](const SmoothingScore& x) {
          return fmt(x.error_delivered) + " (" + fmt(100.0 * (x.error_delivered / raw.error_delivered - 1.0), "%+.1f") + "%) / " +
                 fmt(x.relative_error) + " (" + fmt(100.0 * (x.relative_error / raw.relative_error - 1.0), "%+.1f") + "%)";
        };
        const auto tuned = [&](const char* fam) {
          const auto c = chosen(r, fam, rule, f);
          return c ? pct(r.score[*c][s]) : std::string("none");
        };
        const auto& def = r.score[r.index("posefair-default")][s];
        const auto oe = chosen(r, "one-euro", rule, f);
        std::printf("| %s | %s | %s / %s | %s | %s | %s | %s |\n", r.d->name.c_str(), r.d->sequences[s].name.c_str(),
                    fmt(raw.error_delivered).c_str(), fmt(raw.relative_error).c_str(), pct(def).c_str(), tuned("posefair").c_str(),
                    pct(r.score[r.index("one-euro-default")][s]).c_str(), tuned("one-euro").c_str());
        std::vector<std::string_view> why;
        if (def.error_delivered > 1.01 * raw.error_delivered) why.push_back("absolute error more than 1% above raw");
        if (!(def.relative_error < raw.relative_error)) why.push_back("relative error not below raw");
        if (oe && !(def.relative_error < r.score[*oe][s].relative_error)) why.push_back("relative error not below One Euro tuned");
        if (!why.empty()) {
          std::string line = "low rate, " + r.d->name + " " + r.d->sequences[s].name + ":";
          for (std::size_t k = 0; k < why.size(); ++k) (line += k ? "; " : " ") += why[k];
          losses.push_back(std::move(line));
        }
      }
  }
  std::printf("\n");
}

void print_solvers(const std::vector<SmoothingRuns>& all) {
  std::printf("## Solvers and the ε policy (synthetic sets)\n\n");
  std::printf("Error (b) at the 0 ms budget, mean over the report seeds (rad); each solver tuned on the training seeds\n"
              "over its own grid; ns per sample in brackets.\n\n");
  std::printf("| data set | raw | linear (posefair tuned) | Gauss–Newton | paper's sweeps (K = 4) | One Euro tuned |\n|---|---|---|---|---|---|\n");
  const SelectionRule& rule = kSelectionRules[0];
  for (const SmoothingRuns& r : all) {
    if (r.d->kind != "synthetic") continue;
    std::printf("| %s | %s", r.d->name.c_str(), fmt(fixed_row(r, "raw", rule).error_b.mean).c_str());
    for (const char* fam : {"posefair", "posefair-gn", "posefair-sweeps", "one-euro"}) {
      const Row row = make_row(r, fam, std::nullopt, rule);
      std::printf(" | %s [%s]", row.found ? fmt(row.error_b.mean).c_str() : "none fits", fmt(row.ns.mean, "%.0f").c_str());
    }
    std::printf(" |\n");
  }
  std::printf("\nThe ε bound at half the noise bound (fixed configurations): error (b) / jitter, means over the report seeds.\n\n");
  std::printf("| data set | linear, per sample | Gauss–Newton, per sample | Gauss–Newton, per window |\n|---|---|---|---|\n");
  for (const SmoothingRuns& r : all) {
    if (r.d->kind != "synthetic") continue;
    std::printf("| %s", r.d->name.c_str());
    for (std::size_t c = 0; c < r.cands.size(); ++c) {
      if (r.cands[c].family != "posefair-bound") continue;
      const Row row = make_row(r, "posefair-bound", c, rule);
      std::printf(" | %s / %s", fmt(row.error_b.mean).c_str(), fmt(row.jitter.mean).c_str());
    }
    std::printf(" |\n");
  }
  std::printf("\n");
}

// ---------------------------------------------------------------------------------------------
// Prediction

struct PredictionRuns {
  const QualityDataset* d = nullptr;
  std::vector<PredictionCandidate> cands;
  std::vector<std::vector<std::vector<PredictionScore>>> score;  // [candidate][horizon][sequence]
  std::vector<std::vector<PredictionScore>> engine;              // posefair default: [horizon][sequence]
  bool engine_stamped_ahead = true;
  double engine_delivery_ms = 0.0;  // largest mean delivery delay of its predicted poses
  Spread noise_floor;               // BROAD: optical_noise_bound over the report sequences
};

PredictionRuns run_prediction(const QualityDataset& d, std::ofstream& runs) {
  PredictionRuns r;
  r.d = &d;
  r.cands = prediction_candidates();
  std::vector<double> hs;
  for (double h : kHorizonsMs) hs.push_back(1e-3 * h);
  const std::size_t n = d.sequences.size();
  r.score.assign(r.cands.size(), std::vector<std::vector<PredictionScore>>(hs.size(), std::vector<PredictionScore>(n)));
  r.engine.assign(hs.size(), std::vector<PredictionScore>(n));
  const bool broad = d.kind == "broad";
  const auto write = [&](std::size_t s, const std::string& fam, const std::string& config, std::size_t k, const PredictionScore& x) {
    runs << d.name << ',' << d.sequences[s].name << ',' << role(d, s) << ',' << fam << ",\"" << config << "\"," << kHorizonsMs[k]
         << ',' << x.error << ',' << x.jitter << '\n';
  };
  for (std::size_t s = 0; s < n; ++s) {
    const QualitySequence& q = d.sequences[s];
    for (std::size_t c = 0; c < r.cands.size(); ++c) {
      const auto ys = r.cands[c].run(q, hs);
      for (std::size_t k = 0; k < hs.size(); ++k) {
        r.score[c][k][s] = score_prediction(q, broad, ys[k], hs[k]);
        write(s, r.cands[c].family, r.cands[c].config, k, r.score[c][k][s]);
      }
    }
    for (std::size_t k = 0; k < hs.size(); ++k) {
      const EnginePrediction p = predict_with_engine(q, hs[k]);
      r.engine_stamped_ahead = r.engine_stamped_ahead && p.stamped_ahead;
      r.engine_delivery_ms = std::max(r.engine_delivery_ms, p.delivery_ms);
      r.engine[k][s] = score_prediction(q, broad, p.pose, hs[k]);
      write(s, "posefair-default", "WindowConfig{} horizon_s=h", k, r.engine[k][s]);
    }
  }
  if (broad)
    for (const QualityFold& f : d.folds)
      for (std::size_t s : f.report) r.noise_floor.add(optical_noise_bound(d.sequences[s]));
  r.noise_floor.finish();
  return r;
}

void print_prediction(const std::vector<PredictionRuns>& all, std::ofstream& summary, std::vector<std::string>& losses) {
  if (all.empty()) return;
  std::printf("## Prediction: the pose for t + h against truth at t + h\n\n");
  std::printf("RMS rotation error (rad), mean over the report sequences (min–max); jitter of the predicted stream\n"
              "(rad/s²) at 20 ms. One Euro + DR tuned: chosen per horizon on the training split. BROAD's truth: the\n"
              "optical sample nearest t + h carried to t + h by the gyroscope (under half a period).\n\n");
  for (const PredictionRuns& r : all) {
    std::printf("### %s\n%s.", r.d->name.c_str(), r.d->split.c_str());
    if (r.noise_floor.count) std::printf(" Truth noise floor (one optical sample, upper bound): %s rad.", format_spread(r.noise_floor).c_str());
    if (!r.engine_stamped_ahead)
      std::printf(" **This engine ignores horizon_s** (its poses are stamped with the sample time): its row is the unpredicted smoothed pose.");
    if (r.engine_delivery_ms > 0.01) std::printf(" posefair delivers its predictions %.2f ms after their sample (mean, worst sequence).", r.engine_delivery_ms);
    std::printf("\n\n| predictor | 10 ms | 20 ms | 30 ms | jitter at 20 ms | configuration at 20 ms |\n|---|---|---|---|---|---|\n");
    const std::size_t hold = 0;
    std::vector<double> best_baseline_20(1, std::numeric_limits<double>::infinity());
    std::string best_name;
    double engine20 = 0.0;
    const auto emit = [&](const std::string& fam, const std::vector<std::optional<std::size_t>>& per_fold_per_h, bool engine) {
      // per_fold_per_h[k * folds + f]: candidate for horizon k, fold f.
      std::string cells, configs;
      Spread jitter20;
      double mean20 = 0.0;
      for (std::size_t k = 0; k < std::size(kHorizonsMs); ++k) {
        Spread e;
        std::vector<std::string> configs_k;
        for (std::size_t f = 0; f < r.d->folds.size(); ++f) {
          const auto c = per_fold_per_h[k * r.d->folds.size() + f];
          if (!engine && !c) continue;
          if (!engine) configs_k.push_back(r.cands[*c].config);
          for (std::size_t s : r.d->folds[f].report) {
            const PredictionScore& x = engine ? r.engine[k][s] : r.score[*c][k][s];
            e.add(x.error);
            if (k == 1) jitter20.add(x.jitter);
          }
        }
        e.finish();
        std::sort(configs_k.begin(), configs_k.end());
        configs_k.erase(std::unique(configs_k.begin(), configs_k.end()), configs_k.end());
        cells += format_spread(e) + " | ";
        if (k == 1) {
          mean20 = e.mean;
          configs = joined(configs_k);
        }
        summary << r.d->name << ',' << kHorizonsMs[k] << ',' << fam << ",\"" << (engine ? "WindowConfig{} horizon_s=h" : joined(configs_k))
                << "\"," << e.count << ',' << e.mean << ',' << e.min << ',' << e.max << '\n';
      }
      jitter20.finish();
      std::printf("| %s | %s%s | %s |\n", row_name(fam).c_str(), cells.c_str(), format_spread(jitter20).c_str(),
                  engine ? "WindowConfig{} with horizon_s = h" : configs.c_str());
      return mean20;
    };
    for (std::size_t c = 0; c < r.cands.size(); ++c) {
      const std::string& fam = r.cands[c].family;
      if (fam == "one-euro-dr") continue;
      const double m = emit(fam, std::vector<std::optional<std::size_t>>(std::size(kHorizonsMs) * r.d->folds.size(), c), false);
      if (fam != "hold" && m < best_baseline_20[0]) best_baseline_20[0] = m, best_name = row_name(fam);
    }
    std::vector<std::size_t> members;
    for (std::size_t c = 0; c < r.cands.size(); ++c)
      if (r.cands[c].family == "one-euro-dr") members.push_back(c);
    std::vector<std::optional<std::size_t>> picks;
    for (std::size_t k = 0; k < std::size(kHorizonsMs); ++k)
      for (const QualityFold& f : r.d->folds)
        picks.push_back(pick_on_training(
            members, f.train, [&](std::size_t c, std::size_t s) { return r.score[c][k][s].error / r.score[hold][k][s].error; },
            [](std::size_t, std::size_t) { return 0.0; }, std::numeric_limits<double>::infinity()));
    const double oe20 = emit("one-euro-dr", picks, false);
    if (oe20 < best_baseline_20[0]) best_baseline_20[0] = oe20, best_name = row_name("one-euro-dr");
    engine20 = emit("posefair-default", std::vector<std::optional<std::size_t>>(picks.size()), true);
    std::printf("\n");
    if (!(engine20 < best_baseline_20[0]))
      losses.push_back("prediction, " + r.d->name + ", 20 ms: posefair default " + fmt(engine20) + " rad against " + best_name + " " +
                       fmt(best_baseline_20[0]) + " rad");
  }
}

// ---------------------------------------------------------------------------------------------

int bench_quality(const std::string& data_dir, const std::string& out_dir, bool quick, const std::vector<std::string>& only) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<QualityDataset> sets;
  try {
    sets = load_quality_datasets(data_dir, quick, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "posefair bench quality: " << e.what() << "\n";
    return exit_code(ErrorKind::NoInput);
  }
  // --set: the named data sets alone (a name, or a kind: "broad", "tum", "bvh", "synthetic").
  for (const std::string& name : only)
    if (std::none_of(sets.begin(), sets.end(), [&](const QualityDataset& d) { return d.name == name || d.kind == name; })) {
      std::cerr << "posefair bench quality: no data set or kind '" << name << "'; there are:";
      for (const QualityDataset& d : sets) std::cerr << " " << d.name;
      std::cerr << "\n";
      return exit_code(ErrorKind::Usage);
    }
  if (!only.empty())
    std::erase_if(sets, [&](const QualityDataset& d) {
      return std::none_of(only.begin(), only.end(), [&](const std::string& n) { return d.name == n || d.kind == n; });
    });
  std::filesystem::create_directories(out_dir);
  std::ofstream runs(out_dir + "/quality-runs.csv"), summary(out_dir + "/quality-summary.csv");
  std::ofstream pruns(out_dir + "/quality-prediction-runs.csv"), psummary(out_dir + "/quality-prediction-summary.csv");
  if (!runs || !summary || !pruns || !psummary) {
    std::cerr << "posefair bench quality: cannot write to " << out_dir << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  runs << "dataset,sequence,role,family,config,error_delivered,error_aligned,lag_ms,raw_shift_ms,delivery_ms,jitter,relative_error,"
          "max_deviation,ns_per_sample\n";
  summary << "dataset,selection,family,config,report_sequences,error_delivered_mean,error_delivered_min,error_delivered_max,"
             "error_aligned_mean,error_aligned_min,error_aligned_max,lag_ms_mean,lag_ms_min,lag_ms_max,jitter_mean,jitter_min,"
             "jitter_max,relative_error_mean,relative_error_min,relative_error_max,delivery_ms_mean,over_budget,ns_per_sample\n";
  pruns << "dataset,sequence,role,family,config,horizon_ms,error,jitter\n";
  psummary << "dataset,horizon_ms,family,config,report_sequences,error_mean,error_min,error_max\n";
  std::vector<SmoothingRuns> smoothing;
  std::vector<PredictionRuns> prediction;
  try {
    for (const QualityDataset& d : sets) {
      const auto t1 = std::chrono::steady_clock::now();
      smoothing.push_back(run_smoothing(d, quick, runs));
      if (d.prediction) prediction.push_back(run_prediction(d, pruns));
      std::size_t samples = 0;
      for (const QualitySequence& q : d.sequences) samples += q.input.size();
      std::fprintf(stderr, "%-26s %2zu sequences, %7zu samples, %3zu configurations, %.1f s\n", d.name.c_str(), d.sequences.size(),
                   samples, smoothing.back().cands.size(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
    }
  } catch (const std::runtime_error& e) {
    std::cerr << "posefair bench quality: " << e.what() << "\n";
    return exit_code(ErrorKind::Software);
  }
  std::vector<std::string> losses;
  print_smoothing(smoothing, summary, losses);
  print_low_rate(smoothing, losses);
  print_prediction(prediction, psummary, losses);
  if (quick || std::any_of(sets.begin(), sets.end(), [](const QualityDataset& d) { return d.kind == "synthetic"; }))
    print_solvers(smoothing);
  std::printf("## Where posefair's defaults lose (%zu)\n\n", losses.size());
  for (const std::string& l : losses) std::printf("- %s\n", l.c_str());
  std::printf("\nwrote %s/quality-runs.csv, quality-summary.csv, quality-prediction-runs.csv, quality-prediction-summary.csv\n",
              out_dir.c_str());
  std::fprintf(stderr, "posefair bench quality: %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return kExitOk;
}

}  // namespace

void add_bench_command(CLI::App& app, int& exit_code) {
  auto* bench = app.add_subcommand("bench", "Measure posefair against reference filters");
  bench->require_subcommand(1);
  auto* quality = bench->add_subcommand("quality", "Error, jitter, lag and prediction on synthetic and recorded data, tuned and reported on separate sequences");
  auto data = std::make_shared<std::string>(benchmark_data_dir().string());  // $POSEFAIR_DATA or ../shared/data
  auto out = std::make_shared<std::string>("build/bench-quality");
  auto quick = std::make_shared<bool>(false);
  auto only = std::make_shared<std::vector<std::string>>();
  quality->add_option("--data", *data, "folder with the recorded data sets (tum/, broad/, bvh/); default $POSEFAIR_DATA, else ../shared/data")->capture_default_str();
  quality->add_option("-o,--output", *out, "folder for the CSV files (quality-runs.csv, quality-summary.csv, quality-prediction-*.csv)")->capture_default_str();
  quality->add_flag("--quick", *quick, "synthetic data only, one noise level, shorter, fewer seeds (seconds, for tests)");
  quality->add_option("--set", *only, "run only this data set or kind (broad, tum, bvh, synthetic); repeat it for several (default: all)");
  quality->callback([=, &exit_code] { exit_code = bench_quality(*data, *out, *quick, *only); });
  add_bench_streams_command(*bench, exit_code);
  add_bench_latency_command(*bench, exit_code);
  add_bench_fusion_command(*bench, exit_code);
  add_bench_gyro_fairing_command(*bench, exit_code);
}

}  // namespace posefair::tools
