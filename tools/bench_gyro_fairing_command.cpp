// posefair bench gyro-fairing (docs/fusion.md, "Gyro-aided fairing"): BROAD's optical
// orientation with added tracker jitter and the trial's real gyroscope, faired with the gyro
// (the engine's defaults, nothing tuned) against the clean optical stream; compared with the
// raw jittered stream, fairing alone at its best cutoff per trial (an oracle, in its favour),
// fairing alone with its defaults, and One Euro tuned on the other trials (leave one out, over
// `bench quality`'s One Euro grid and picker). Every error is the RMS rotation angle to the
// clean optical orientation at the same time, over BROAD's movement phases, with lag 0: any
// delay is charged in the error.
#include "bench_gyro_fairing_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "benchmark_data.hpp"
#include "posefair/core/error.hpp"
#include "quality_configurations.hpp"
#include "quality_datasets.hpp"
#include "quality_scoring.hpp"
#include "quality_tuning.hpp"

namespace posefair::tools {

namespace {

namespace fs = std::filesystem;

const char* const kTrials[] = {"02_undisturbed_slow_rotation_B",
                               "05_undisturbed_slow_rotation_with_breaks_B",
                               "07_undisturbed_fast_rotation_B",
                               "16_undisturbed_fast_translation_B",
                               "21_undisturbed_fast_combined",
                               "25_disturbed_tapping_B",
                               "27_disturbed_phone_vibration_B",
                               "29_disturbed_stationary_magnet_B",
                               "33_disturbed_attached_magnet_2cm"};

// Fairing alone: fixed cutoffs (Hz), of which each trial gets its best.
const double kCutoffs[] = {0.5, 0.71, 1.0, 1.41, 2.0, 2.83, 4.0, 5.66, 8.0, 11.3, 16.0, 22.6, 32.0, 45.3};

// The trial with white jitter of `jitter_deg` RMS rotation angle (Gaussian rotation vectors).
PoseSequence jittered(const QualitySequence& q, double jitter_deg, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, jitter_deg * M_PI / 180.0 / std::sqrt(3.0));
  PoseSequence p = q.input;
  for (Quat& o : p.orientation) o = (o * so3::from_rotation_vector(Vec3(n(rng), n(rng), n(rng)))).normalized();
  return p;
}

// RMS rotation angle (degrees) to the clean optical orientation over the scored samples.
double error_deg(const QualitySequence& clean, const std::vector<Quat>& pose) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < pose.size(); ++i) {
    if (!clean.use[i]) continue;
    const double a = so3::rotation_angle(pose[i], clean.input.orientation[i]);
    sum += a * a;
    ++count;
  }
  return count ? std::sqrt(sum / static_cast<double>(count)) * 180.0 / M_PI : 0.0;
}

struct TrialScores {
  double raw = 0.0, fairing_default = 0.0, gyro = 0.0, gyro_no_offset = 0.0;
  std::vector<double> fairing;   // per cutoff
  std::vector<double> one_euro;  // per One Euro candidate
  Vec3 bias = Vec3::Zero();      // estimated, rad/s (last seed)
  double offset_ms = 0.0;        // estimated (mean over seeds)
};

int bench_gyro_fairing(const std::string& data, const std::string& out_dir, int seeds) {
  const auto t0 = std::chrono::steady_clock::now();
  QualityDataset d;
  d.name = "broad";
  d.kind = "broad";
  for (const char* t : kTrials) {
    const std::string rel = std::string("broad/") + t + ".csv";
    if (!fs::exists(fs::path(data) / rel)) continue;
    try {
      d.sequences.push_back(broad_sequence(fs::path(data) / rel, t));
    } catch (const std::exception& e) {
      std::cerr << "posefair bench gyro-fairing: " << e.what() << "\n";
      return exit_code(ErrorKind::DataErr);
    }
  }
  if (d.sequences.size() < 2) {
    std::cerr << "posefair bench gyro-fairing: needs at least two BROAD trials: "
              << missing_file_line(data, std::string("broad/") + kTrials[2] + ".csv") << "\n"
              << where_benchmark_data_is_looked_for() << "\n";
    return exit_code(ErrorKind::NoInput);
  }
  // One Euro: `bench quality`'s grid for this data set.
  std::vector<SmoothingCandidate> euro;
  for (SmoothingCandidate& c : smoothing_candidates(d, false))
    if (c.family == "one-euro") euro.push_back(std::move(c));

  fs::create_directories(out_dir);
  std::ofstream csv(fs::path(out_dir) / "gyro-fairing-trials.csv");
  csv << "jitter_deg,trial,raw_deg,fairing_best_deg,fairing_best_cutoff_hz,fairing_default_deg,one_euro_loo_deg,"
         "gyro_aided_deg,gyro_aided_no_offset_deg,ratio_to_fairing_best,offset_ms,bias_x,bias_y,bias_z\n";
  std::printf("# Gyro-aided fairing on BROAD: %zu trials, %d seeds per jitter, RMS angle (°) to the clean optical "
              "orientation over movement phases, lag 0\n\n",
              d.sequences.size(), seeds);
  bool all_met = true;
  for (const double jitter : {0.5, 1.0}) {
    const double goal = jitter < 0.75 ? 0.75 : 0.6;
    std::vector<TrialScores> rows(d.sequences.size());
    for (std::size_t t = 0; t < d.sequences.size(); ++t) {
      const QualitySequence& clean = d.sequences[t];
      TrialScores& r = rows[t];
      r.fairing.assign(std::size(kCutoffs), 0.0);
      r.one_euro.assign(euro.size(), 0.0);
      for (int s = 0; s < seeds; ++s) {
        QualitySequence q = clean;
        q.input = jittered(clean, jitter, 1000u * (t + 1) + static_cast<std::uint64_t>(s) + (jitter < 0.75 ? 0u : 500000u));
        r.raw += error_deg(clean, q.input.orientation) / seeds;
        WindowConfig base;
        base.rate_hz = clean.rate_hz;
        r.fairing_default += error_deg(clean, run_engine(q.input, base).pose) / seeds;
        for (std::size_t c = 0; c < std::size(kCutoffs); ++c) {
          WindowConfig f = base;
          f.cutoff_hz = kCutoffs[c];
          r.fairing[c] += error_deg(clean, run_engine(q.input, f).pose) / seeds;
        }
        for (std::size_t c = 0; c < euro.size(); ++c) r.one_euro[c] += error_deg(clean, euro[c].run(q).pose) / seeds;
        EngineState state;
        r.gyro += error_deg(clean, run_engine(q.input, base, clean.gyro, &state).pose) / seeds;
        r.bias = state.gyro.bias;
        r.offset_ms += 1e3 * state.gyro.time_offset_s / seeds;
        WindowConfig fixed = base;
        fixed.gyro.estimate_time_offset = false;
        r.gyro_no_offset += error_deg(clean, run_engine(q.input, fixed, clean.gyro).pose) / seeds;
      }
    }
    std::printf("## Jitter %.1f° RMS (goal: gyro-aided ≤ %.2f × fairing alone at its best cutoff on every trial)\n\n", jitter,
                goal);
    std::printf("| trial | raw | fairing alone, best cutoff | fairing alone, defaults | One Euro, tuned on the other trials | "
                "gyro-aided (defaults) | gyro-aided, δ = 0 | ratio to fairing best | estimated δ (ms) | estimated bias (°/s) |\n"
                "|---|---|---|---|---|---|---|---|---|---|\n");
    std::vector<double> sums(6, 0.0);
    for (std::size_t t = 0; t < rows.size(); ++t) {
      const TrialScores& r = rows[t];
      const auto best = static_cast<std::size_t>(std::min_element(r.fairing.begin(), r.fairing.end()) - r.fairing.begin());
      // One Euro: the candidate with the lowest mean error relative to raw on the other trials.
      std::vector<std::size_t> candidates(euro.size()), train;
      for (std::size_t c = 0; c < euro.size(); ++c) candidates[c] = c;
      for (std::size_t o = 0; o < rows.size(); ++o)
        if (o != t) train.push_back(o);
      const auto pick = pick_on_training(
          candidates, train, [&](std::size_t c, std::size_t o) { return rows[o].one_euro[c] / rows[o].raw; },
          [](std::size_t, std::size_t) { return 0.0; }, 0.0);
      const double euro_err = pick ? r.one_euro[*pick] : std::nan("");
      const double ratio = r.gyro / r.fairing[best];
      all_met = all_met && ratio <= goal;
      const std::string name = broad_trial_number(d.sequences[t].name);
      std::printf("| %s | %.3f | %.3f (%g Hz) | %.3f | %.3f (%s) | %.3f | %.3f | %.2f%s | %.1f | %.2f |\n", name.c_str(), r.raw,
                  r.fairing[best], kCutoffs[best], r.fairing_default, euro_err, pick ? euro[*pick].config.c_str() : "-", r.gyro,
                  r.gyro_no_offset, ratio, ratio <= goal ? "" : " **missed**", r.offset_ms, r.bias.norm() * 180.0 / M_PI);
      csv << jitter << ',' << name << ',' << r.raw << ',' << r.fairing[best] << ',' << kCutoffs[best] << ',' << r.fairing_default
          << ',' << euro_err << ',' << r.gyro << ',' << r.gyro_no_offset << ',' << ratio << ',' << r.offset_ms << ',' << r.bias.x()
          << ',' << r.bias.y() << ',' << r.bias.z() << "\n";
      const double v[] = {r.raw, r.fairing[best], r.fairing_default, euro_err, r.gyro, r.gyro_no_offset};
      for (std::size_t i = 0; i < 6; ++i) sums[i] += v[i];
    }
    const double n = static_cast<double>(rows.size());
    std::printf("| **mean** | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | | |\n\n", sums[0] / n, sums[1] / n, sums[2] / n,
                sums[3] / n, sums[4] / n, sums[5] / n, sums[4] / sums[1]);
  }
  std::printf("goal (every trial, both jitters): %s\n", all_met ? "met" : "NOT met");
  std::printf("wrote %s/gyro-fairing-trials.csv\n", out_dir.c_str());
  std::fprintf(stderr, "posefair bench gyro-fairing: %.1f s\n",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return kExitOk;
}

}  // namespace

void add_bench_gyro_fairing_command(CLI::App& bench, int& exit_code) {
  auto* cmd = bench.add_subcommand("gyro-fairing", "Gyro-aided fairing on BROAD with added jitter, against fairing alone and One Euro");
  auto data = std::make_shared<std::string>(benchmark_data_dir().string());
  auto out = std::make_shared<std::string>("build/bench-gyro-fairing");
  auto seeds = std::make_shared<int>(5);
  cmd->add_option("--data", *data, "folder with broad/ (the trial CSVs); default $POSEFAIR_DATA, else ../shared/data")->capture_default_str();
  cmd->add_option("-o,--output", *out, "folder for gyro-fairing-trials.csv")->capture_default_str();
  cmd->add_option("--seeds", *seeds, "jitter seeds per trial and jitter level")->check(CLI::Range(1, 100))->capture_default_str();
  cmd->callback([=, &exit_code] { exit_code = bench_gyro_fairing(*data, *out, *seeds); });
}

}  // namespace posefair::tools
