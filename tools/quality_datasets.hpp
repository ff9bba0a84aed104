#pragma once
// The data sets of `posefair bench quality` (docs/benchmarks.md), each a group of sequences
// with a tuning split: configurations are tuned on the Train sequences of a fold and reported
// on its Report sequences, never on the data they were tuned on.
//   synthetic-<rate>-noise<n>  smooth motion plus bounded noise, split by seed (3 train, 5 report)
//   tum-30Hz, tum-10Hz         TUM RGB-D SLAM estimates (as recorded, and decimated to 10 Hz)
//                              against motion capture; two folds, each set tuning the other
//   broad                      BROAD's optical orientation against its gyroscope, split by trial
//   bvh                        BVH joints with added noise against the clean file, split by
//                              joint and file (tuned on CMU 01_01, reported on Boxing_Toes)
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "posefair/core/pose_sequence.hpp"

namespace posefair::tools {

// A truth orientation as a function of time: samples joined by normalised linear interpolation
// (nearly slerp) where neighbours are at most max_gap apart. Queries are answered through a caller's cursor, O(1) when they move
// forward, as every scoring pass does.
class TruthTrack {
 public:
  TruthTrack() = default;
  TruthTrack(std::vector<double> time, std::vector<Quat> orientation, double max_gap);
  bool empty() const { return time_.empty(); }
  // The truth at t into out; false when t is outside the track or inside a gap.
  bool at(double t, Quat& out, std::size_t& cursor) const;
  const std::vector<double>& time() const { return time_; }

 private:
  std::vector<double> time_;
  std::vector<Quat> q_;
  double max_gap_ = 0.0;
};

struct QualitySequence {
  std::string name;
  PoseSequence input;        // orientation only: what every smoother and predictor sees
  TruthTrack truth;          // empty for BROAD
  std::vector<Vec3> gyro;    // BROAD: per input sample, rad/s, body frame
  double gyro_shift = 0.0;   // BROAD: the optical stream's own shift to the gyroscope (s)
  double truth_shift = 0.0;  // TUM: how far the estimate's clock trails motion capture's (s); the truth is moved by it
  std::vector<char> use;     // input samples that are scored
  double rate_hz = 0.0;      // nominal (median) sample rate
};

struct QualityFold {
  std::vector<std::size_t> train, report;  // indices into QualityDataset::sequences
};

struct QualityDataset {
  std::string name;
  std::string kind;          // "synthetic", "tum", "broad", "bvh"
  std::string split;         // how it is split, in words, for the tables
  std::vector<QualitySequence> sequences;
  std::vector<QualityFold> folds;
  bool prediction = false;   // also scored for prediction (BROAD, BVH, synthetic)
};

// Loads every data set; the recorded ones in full from data_dir ($POSEFAIR_DATA or
// ../shared/data, benchmark_data.hpp). quick: the synthetic ones only, shorter, 1 train and
// 2 report seeds. A recorded set with a missing file is skipped with a line on notes (a data set
// keeps the sequences that are there and runs while both splits have one); throws
// std::runtime_error naming a file that is malformed, or, when no recorded file is there at
// all, every file and where it comes from.
std::vector<QualityDataset> load_quality_datasets(const std::filesystem::path& data_dir, bool quick, std::ostream& notes);

// One BROAD trial: the optical orientation (dropouts left out), the gyroscope at the same rows,
// scored in the movement phases (use), and the optical stream's measured shift to the gyroscope.
// Throws std::runtime_error naming the file and line of anything malformed.
QualitySequence broad_sequence(const std::filesystem::path& path, const std::string& name);

// A BROAD trial's number, "07" of "07_undisturbed_fast_rotation_B", for tables.
inline std::string broad_trial_number(const std::string& trial) { return trial.substr(0, trial.find('_')); }

}  // namespace posefair::tools
