#include "bench_streams_command.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "generated_streams.hpp"
#include "posefair/core/error.hpp"
#include "posefair/core/upper_median.hpp"
#include "quality_configurations.hpp"
#include "quality_scoring.hpp"

namespace posefair::tools {
namespace {

// The default is "near" a configuration picked on the stream itself when within this much of it.
constexpr double kNear = 0.10;
// ...and above raw when more than this over it.
constexpr double kAboveRaw = 0.01;

struct Best {
  double error = 0.0;
  std::string config;
};

struct StreamRow {
  GeneratedStreamSpec spec;
  double raw = 0.0, fair = 0.0, one_euro = 0.0;  // error (a), rad
  double raw_jitter = 0.0, fair_jitter = 0.0;
  Best best_fair, best_one_euro;
};

// Each family's configurations at lag 0 (the default's own latency), the best of them on this
// stream by error (a): an upper bound on what tuning either family for this stream could do.
StreamRow run_stream(const GeneratedStreamSpec& spec) {
  QualityDataset d;
  d.name = spec.name();
  d.kind = "generated";
  d.sequences.push_back(generated_stream(spec));
  const QualitySequence& q = d.sequences.front();
  StreamRow row;
  row.spec = spec;
  row.best_fair.error = row.best_one_euro.error = std::numeric_limits<double>::infinity();
  for (const SmoothingCandidate& c : smoothing_candidates(d, false)) {
    const bool lag0 = c.family != "posefair" || c.config.ends_with("lag=0");
    if (!lag0 || (c.family != "raw" && c.family != "posefair-default" && c.family != "one-euro-default" && c.family != "posefair" &&
                  c.family != "one-euro"))
      continue;
    const SmoothingScore s = score_smoothing(q, false, c.run(q));
    if (c.family == "raw") {
      row.raw = s.error_delivered;
      row.raw_jitter = s.jitter;
    } else if (c.family == "posefair-default") {
      row.fair = s.error_delivered;
      row.fair_jitter = s.jitter;
    } else if (c.family == "one-euro-default") {
      row.one_euro = s.error_delivered;
    } else {
      Best& best = c.family == "posefair" ? row.best_fair : row.best_one_euro;
      if (s.error_delivered < best.error) best = {s.error_delivered, c.config};
    }
  }
  // The default is one of posefair's configurations a user can pick.
  if (row.fair < row.best_fair.error) row.best_fair = {row.fair, "WindowConfig{}"};
  return row;
}

std::string pct(double x, double ref) {
  char b[32];
  std::snprintf(b, sizeof b, "%+.1f%%", 100.0 * (x / ref - 1.0));
  return b;
}

double median(std::vector<double> v) { return v.empty() ? 0.0 : upper_median(v); }

int bench_streams(const std::string& out_dir, bool quick) {
  const auto t0 = std::chrono::steady_clock::now();
  std::filesystem::create_directories(out_dir);
  std::ofstream csv(out_dir + "/streams.csv");
  if (!csv) {
    std::cerr << "posefair bench streams: cannot write to " << out_dir << "\n";
    return exit_code(ErrorKind::CantCreate);
  }
  csv << "stream,motion,rate_hz,noise,raw,default,one_euro_default,best_posefair,best_posefair_config,best_one_euro,"
         "best_one_euro_config,raw_jitter,default_jitter,source_hz,resampling,dropouts_per_s,lost_per_s,burst_factor\n";
  std::vector<StreamRow> rows;
  for (const GeneratedStreamSpec& spec : generated_stream_specs(quick)) {
    rows.push_back(run_stream(spec));
    const StreamRow& r = rows.back();
    csv << spec.name() << ',' << spec.motion << ',' << spec.rate_hz << ',' << spec.noise << ',' << r.raw << ',' << r.fair << ','
        << r.one_euro << ',' << r.best_fair.error << ",\"" << r.best_fair.config << "\"," << r.best_one_euro.error << ",\""
        << r.best_one_euro.config << "\"," << r.raw_jitter << ',' << r.fair_jitter << ',' << spec.source_hz << ',' << spec.resampling
        << ',' << spec.dropouts_per_s << ',' << spec.lost_per_s << ',' << spec.burst_factor << '\n';
  }

  std::printf("## Generated streams: the defaults where nothing was tuned\n\n");
  std::printf("%zu streams (%s), error (a) in rad, RMS at the delivery time, the first second left out; percentages against\n"
              "raw. Best on the stream: each family's lowest error among its configurations at lag 0, picked on that stream\n"
              "itself (posefair: m × 10 smoothings × 2 windows; One Euro: 80), an upper bound on what tuning it could do.\n\n",
              rows.size(), quick ? "--quick" : "5 motions × 6 rates × 4 noise levels, 4 motions measured at 60 Hz, resampled to 250 Hz 2 ways, 4 motions at 120 Hz under 2 noise levels with dropouts, the same at 60 Hz with lost packets, and 4 motions at 60 and 250 Hz with noise bursts");
  std::printf("| stream | raw | posefair default | best posefair on the stream | default against it | One Euro default | best One Euro on the stream | default against it |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const StreamRow& r : rows)
    std::printf("| %s | %.4g | %.4g (%s) | %.4g (%s) %s | %s | %.4g (%s) | %.4g (%s) %s | %s |\n", r.spec.name().c_str(), r.raw, r.fair,
                pct(r.fair, r.raw).c_str(), r.best_fair.error, pct(r.best_fair.error, r.raw).c_str(), r.best_fair.config.c_str(),
                pct(r.fair, r.best_fair.error).c_str(), r.one_euro, pct(r.one_euro, r.raw).c_str(), r.best_one_euro.error,
                pct(r.best_one_euro.error, r.raw).c_str(), r.best_one_euro.config.c_str(), pct(r.fair, r.best_one_euro.error).c_str());

  // The summary: where the default is above raw, how far from the best posefair configuration
  // for each stream, and against the best One Euro for each stream.
  std::vector<std::string> above_raw;
  std::vector<double> to_best, to_one_euro;
  std::size_t near_best = 0, below_one_euro = 0;
  const StreamRow* worst = nullptr;
  for (const StreamRow& r : rows) {
    if (r.fair > (1.0 + kAboveRaw) * r.raw) above_raw.push_back(r.spec.name() + " " + pct(r.fair, r.raw));
    to_best.push_back(r.fair / r.best_fair.error - 1.0);
    to_one_euro.push_back(r.fair / r.best_one_euro.error - 1.0);
    near_best += r.fair <= (1.0 + kNear) * r.best_fair.error;
    below_one_euro += r.fair < r.best_one_euro.error;
    if (!worst || r.fair / r.best_fair.error > worst->fair / worst->best_fair.error) worst = &r;
  }
  std::printf("\n- above raw by more than %.0f%%: %zu of %zu", 100.0 * kAboveRaw, above_raw.size(), rows.size());
  for (std::size_t i = 0; i < above_raw.size(); ++i) std::printf("%s%s", i ? ", " : ": ", above_raw[i].c_str());
  std::printf("\n- within %.0f%% of the best posefair configuration for the stream: %zu of %zu (median %+.1f%%", 100.0 * kNear, near_best,
              rows.size(), 100.0 * median(to_best));
  if (worst) std::printf(", worst %s on %s", pct(worst->fair, worst->best_fair.error).c_str(), worst->spec.name().c_str());
  std::printf(")\n- below the best One Euro for the stream: %zu of %zu (median %+.1f%%)\n\n", below_one_euro, rows.size(),
              100.0 * median(to_one_euro));
  std::fprintf(stderr, "posefair bench streams: %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return kExitOk;
}

}  // namespace

void add_bench_streams_command(CLI::App& bench, int& exit_code) {
  auto* cmd = bench.add_subcommand("streams", "posefair's defaults on generated motions, rates and noise levels, against the best configuration for each stream");
  auto out = std::make_shared<std::string>("build/bench-streams");
  auto quick = std::make_shared<bool>(false);
  cmd->add_option("-o,--output", *out, "folder for streams.csv")->capture_default_str();
  cmd->add_flag("--quick", *quick, "four short streams (seconds, for tests)");
  cmd->callback([=, &exit_code] { exit_code = bench_streams(*out, *quick); });
}

}  // namespace posefair::tools
