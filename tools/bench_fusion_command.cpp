// posefair bench fusion (docs/fusion.md): every BROAD trial found in <data>/broad, each
// estimator run from the trial's first sample with one parameter set for all trials (TAGP),
// scored by BROAD's RMSE (orientation_error.hpp) over movement = 1 with a valid optical
// reference, averaged per trial group of trials.json.
#include "bench_fusion_command.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "benchmark_data.hpp"
#include "fusion_run.hpp"
#include "quality_datasets.hpp"
#include "posefair/core/error.hpp"
#include "posefair/core/orientation_error.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {

namespace {

namespace fs = std::filesystem;

// BROAD's published Madgwick results at its TAGP (beta = 0.12), total RMSE in degrees
// (example_code/out/results_madgwick_average_rmse.json of the BROAD repository).
const std::map<std::string, double> kPublishedMadgwick = {
    {"02_undisturbed_slow_rotation_B", 1.50}, {"05_undisturbed_slow_rotation_with_breaks_B", 1.79},
    {"07_undisturbed_fast_rotation_B", 5.00}, {"16_undisturbed_fast_translation_B", 4.82},
    {"21_undisturbed_fast_combined", 7.16},   {"25_disturbed_tapping_B", 3.92},
    {"27_disturbed_phone_vibration_B", 10.62}, {"29_disturbed_stationary_magnet_B", 9.16},
    {"33_disturbed_attached_magnet_2cm", 7.09},
};

struct FusionTrial {
  std::string name;
  formats::ImuRecording recording;
  std::vector<Quat> reference;
  std::vector<std::uint8_t> scored;
  std::vector<std::string> groups;
};

struct FusionMethod {
  std::string label;      // column heading
  std::string estimator;  // registry name
  OptionMap options;
  bool six_d = false;
};

std::vector<FusionTrial> load_broad_trials(const fs::path& dir) {
  const fs::path broad = dir / "broad";
  const fs::path index = broad / "trials.json";
  if (!fs::exists(index)) {
    throw std::runtime_error("no BROAD data found: " + missing_file_line(dir, "broad/trials.json") + "\n" +
                             where_benchmark_data_is_looked_for());
  }
  std::ifstream in(index);
  const nlohmann::json info = nlohmann::json::parse(in);
  std::vector<FusionTrial> trials;
  for (const auto& [name, trial] : info.at("trials").items()) {
    const fs::path csv = broad / (name + ".csv");
    if (!fs::exists(csv)) continue;  // trials.json lists all 39; the data set may hold fewer
    FusionTrial t;
    t.name = name;
    for (const auto& g : trial.at("groups")) t.groups.push_back(g.get<std::string>());
    t.recording = formats::read_imu_csv(csv);
    for (std::size_t k = 0; k < t.recording.samples.size(); ++k) {
      const Sample& s = t.recording.samples[k];
      t.reference.push_back(s.has_orientation() ? s.orientation : Quat::Identity());
      t.scored.push_back(s.has_orientation() && t.recording.movement[k] != 0 ? 1 : 0);
    }
    trials.push_back(std::move(t));
  }
  if (trials.empty())
    throw std::runtime_error("no BROAD trial CSV found beside " + index.string() + "\n" +
                             where_benchmark_data_is_looked_for());
  std::sort(trials.begin(), trials.end(), [](const FusionTrial& a, const FusionTrial& b) { return a.name < b.name; });
  return trials;
}

OrientationRmse score_fusion(const FusionTrial& t, const FusionMethod& m) {
  OptionMap options = m.options;
  options["magnetometer"] = !m.six_d;
  const auto estimator = make_orientation_estimator(m.estimator, options);
  const std::vector<Quat> estimate = run_estimator(*estimator, t.recording);
  return orientation_rmse(estimate, t.reference, t.scored);
}

double fusion_metric(const OrientationRmse& r, bool six_d) { return six_d ? r.inclination_deg : r.total_deg; }

// The beta with the lowest mean error over all trials (BROAD's TAGP), on BROAD's grid.
double madgwick_tagp_beta(const std::vector<FusionTrial>& trials, bool six_d) {
  double best_beta = 0.0, best = 1e300;
  for (int i = 1; i <= 30; ++i) {
    const double beta = 0.01 * i;
    double sum = 0.0;
    for (const FusionTrial& t : trials) sum += fusion_metric(score_fusion(t, {"", "madgwick", {{"beta", beta}}, six_d}), six_d);
    if (sum < best) {
      best = sum;
      best_beta = beta;
    }
  }
  return best_beta;
}

int bench_fusion(const std::string& data, const std::string& out_dir, bool grid) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<FusionTrial> trials;
  try {
    trials = load_broad_trials(data);
  } catch (const std::exception& e) {
    std::cerr << "posefair bench fusion: " << e.what() << "\n";
    return exit_code(ErrorKind::NoInput);
  }
  const double beta6 = grid ? madgwick_tagp_beta(trials, true) : 0.12;
  char beta6_label[64];
  std::snprintf(beta6_label, sizeof beta6_label, "Madgwick 6D (β=%.2f)", beta6);
  const std::vector<FusionMethod> methods = {
      {"Madgwick (β=0.12)", "madgwick", {{"beta", 0.12}, {"c_code_field", true}}, false},
      {"Mahony (Kp=0.74, Ki=0.0012)", "mahony", {{"kp", 0.74}, {"ki", 0.0012}}, false},
      {"VQF", "vqf", {}, false},
      {beta6_label, "madgwick", {{"beta", beta6}}, true},
      {"Mahony 6D (Kp=0.74, Ki=0.0012)", "mahony", {{"kp", 0.74}, {"ki", 0.0012}}, true},
      {"VQF 6D", "vqf", {}, true},
  };

  std::vector<std::vector<OrientationRmse>> results(trials.size());
  for (std::size_t i = 0; i < trials.size(); ++i)
    for (const FusionMethod& m : methods) results[i].push_back(score_fusion(trials[i], m));

  fs::create_directories(out_dir);
  std::ofstream csv(fs::path(out_dir) / "fusion-trials.csv");
  csv << "trial,method,mode,total_deg,heading_deg,inclination_deg,published_madgwick_total_deg\n";
  for (std::size_t i = 0; i < trials.size(); ++i)
    for (std::size_t j = 0; j < methods.size(); ++j) {
      const auto published = kPublishedMadgwick.find(trials[i].name);
      csv << broad_trial_number(trials[i].name) << ",\"" << methods[j].label << "\"," << (methods[j].six_d ? "6D" : "9D") << ','
          << results[i][j].total_deg << ',' << results[i][j].heading_deg << ',' << results[i][j].inclination_deg << ','
          << (published != kPublishedMadgwick.end() ? std::to_string(published->second) : "") << "\n";
    }

  const auto table = [&](bool six_d) {
    std::printf("## %s\n\n| trial |%s", six_d ? "6D: inclination RMSE (°)" : "9D: total RMSE (°)",
                six_d ? "" : " BROAD's Madgwick |");
    for (const FusionMethod& m : methods)
      if (m.six_d == six_d) std::printf(" %s |", m.label.c_str());
    std::printf("\n|---|%s", six_d ? "" : "---|");
    for (const FusionMethod& m : methods)
      if (m.six_d == six_d) std::printf("---|");
    std::printf("\n");
    std::vector<double> sums(methods.size(), 0.0);
    double published_sum = 0.0;
    std::size_t published_n = 0;
    for (std::size_t i = 0; i < trials.size(); ++i) {
      std::printf("| %s |", broad_trial_number(trials[i].name).c_str());
      if (!six_d) {
        const auto p = kPublishedMadgwick.find(trials[i].name);
        if (p != kPublishedMadgwick.end()) {
          std::printf(" %.2f |", p->second);
          published_sum += p->second;
          ++published_n;
        } else {
          std::printf(" |");
        }
      }
      for (std::size_t j = 0; j < methods.size(); ++j)
        if (methods[j].six_d == six_d) {
          std::printf(" %.2f |", fusion_metric(results[i][j], six_d));
          sums[j] += fusion_metric(results[i][j], six_d);
        }
      std::printf("\n");
    }
    std::printf("| **mean** |");
    if (!six_d) std::printf(" %.2f |", published_n > 0 ? published_sum / static_cast<double>(published_n) : 0.0);
    for (std::size_t j = 0; j < methods.size(); ++j)
      if (methods[j].six_d == six_d) std::printf(" **%.2f** |", sums[j] / static_cast<double>(trials.size()));
    std::printf("\n\n");
  };
  std::printf("# BROAD: %zu trials, scored over movement = 1 with optical data\n\n", trials.size());
  table(false);
  table(true);

  // Per group (trials.json), over the trials present.
  std::vector<std::string> group_names;
  for (const FusionTrial& t : trials)
    for (const std::string& g : t.groups)
      if (std::find(group_names.begin(), group_names.end(), g) == group_names.end()) group_names.push_back(g);
  std::printf("## Per group: mean over the trials present (9D total / 6D inclination, °)\n\n| group | trials |");
  for (const FusionMethod& m : methods) std::printf(" %s |", m.label.c_str());
  std::printf("\n|---|---|");
  for (std::size_t j = 0; j < methods.size(); ++j) std::printf("---|");
  std::printf("\n");
  std::ofstream gcsv(fs::path(out_dir) / "fusion-groups.csv");
  gcsv << "group,trials,method,mode,value_deg\n";
  for (const std::string& g : group_names) {
    std::vector<std::size_t> members;
    for (std::size_t i = 0; i < trials.size(); ++i)
      if (std::find(trials[i].groups.begin(), trials[i].groups.end(), g) != trials[i].groups.end()) members.push_back(i);
    std::printf("| %s | %zu |", g.c_str(), members.size());
    for (std::size_t j = 0; j < methods.size(); ++j) {
      double sum = 0.0;
      for (std::size_t i : members) sum += fusion_metric(results[i][j], methods[j].six_d);
      const double mean = sum / static_cast<double>(members.size());
      std::printf(" %.2f |", mean);
      gcsv << g << ',' << members.size() << ",\"" << methods[j].label << "\"," << (methods[j].six_d ? "6D" : "9D") << ','
           << mean << "\n";
    }
    std::printf("\n");
  }
  std::printf("\nwrote %s/fusion-trials.csv, fusion-groups.csv\n", out_dir.c_str());
  std::fprintf(stderr, "posefair bench fusion: %.1f s\n",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return kExitOk;
}

}  // namespace

void add_bench_fusion_command(CLI::App& bench, int& exit_code) {
  auto* cmd = bench.add_subcommand("fusion", "Orientation estimators on BROAD against Madgwick, Mahony and BROAD's published figures");
  auto data = std::make_shared<std::string>(benchmark_data_dir().string());
  auto out = std::make_shared<std::string>("build/bench-fusion");
  auto no_grid = std::make_shared<bool>(false);
  cmd->add_option("--data", *data, "folder with broad/ (trials.json and the trial CSVs); default $POSEFAIR_DATA, else ../shared/data")->capture_default_str();
  cmd->add_option("-o,--output", *out, "folder for fusion-trials.csv and fusion-groups.csv")->capture_default_str();
  cmd->add_flag("--no-grid", *no_grid, "skip the search for Madgwick's 6D TAGP beta (use 0.12)");
  cmd->callback([=, &exit_code] { exit_code = bench_fusion(*data, *out, !*no_grid); });
}

}  // namespace posefair::tools
