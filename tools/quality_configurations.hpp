#pragma once
// What `posefair bench quality` runs on each data set (docs/benchmarks.md, "Rows"):
//   smoothing: raw; posefair's defaults (WindowConfig{}, nothing set); One Euro's defaults
//   (mincutoff 1 Hz, β 0, dcutoff 1 Hz); and the tuned families, each a grid in physical units
//   whose configurations are the same on every sequence of a data set: posefair and One Euro
//   80 configurations each, the exponential slerp filter 8; on the synthetic sets also the
//   Gauss–Newton and damped-sweeps solvers and the ε policies, for the solver tables.
//   prediction: holding the newest sample, dead reckoning, slerp extrapolation, One Euro with
//   dead reckoning (defaults, and a grid of 80), and posefair's defaults with a horizon.
#include <functional>
#include <string>
#include <vector>

#include "quality_datasets.hpp"
#include "quality_scoring.hpp"

namespace posefair::tools {

// Families whose configuration is picked on the training split, and the fixed rows.
inline constexpr const char* kTunedFamilies[] = {"posefair", "one-euro", "slerp", "posefair-gn", "posefair-sweeps"};

struct SmoothingCandidate {
  std::string family;  // "raw", "posefair-default", "one-euro-default", a tuned family, "posefair-bound"
  std::string config;  // the same text on every sequence of the data set
  std::function<DeliveredStream(const QualitySequence&)> run;
  bool default_engine = false;  // WindowConfig{}: checked against fair_causal
};

// The candidates for a data set; the grids span the cutoffs its slowest sequence allows.
std::vector<SmoothingCandidate> smoothing_candidates(const QualityDataset& d, bool quick);

struct PredictionCandidate {
  std::string family;  // "hold", "dead-reckoning", "slerp-extrapolation", "one-euro-dr-default", "one-euro-dr"
  std::string config;
  // One predicted stream per horizon: out[h][i] is the pose predicted from samples up to i
  // for input.time[i] + horizons[h].
  std::function<std::vector<std::vector<Quat>>(const QualitySequence&, const std::vector<double>& horizons)> run;
};

// The baselines (posefair's row is predict_with_engine); One Euro's grid is tuned per horizon.
std::vector<PredictionCandidate> prediction_candidates();

// posefair's defaults with a horizon (WindowConfig c; c.horizon_s = h; nothing else), through
// run_engine: the predicted poses, and whether the engine stamped them with sample time + h (an
// engine that ignores horizon_s does not). Throws std::runtime_error if the poses differ from
// fair_causal's.
struct EnginePrediction {
  std::vector<Quat> pose;
  bool stamped_ahead = true;
  double delivery_ms = 0.0;  // mean delay from a sample's arrival to its pose's delivery
};
EnginePrediction predict_with_engine(const QualitySequence& q, double horizon_s);

}  // namespace posefair::tools
