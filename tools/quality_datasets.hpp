#pragma once
// The data sets of `posefair bench quality` (docs/benchmarks.md): synthetic streams with known
// truth, TUM SLAM estimates against motion capture, BROAD optical orientation against its
// gyroscope, and BVH joints with added noise against the clean file.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "posefair/core/pose_sequence.hpp"

namespace posefair::tools {

struct QualityDataset {
  std::string name;
  std::string kind;            // "synthetic", "tum", "broad", "bvh"
  PoseSequence input;          // orientation only: what the smoother sees
  std::vector<Quat> truth;     // per input sample (empty for BROAD)
  std::vector<Vec3> gyro;      // per input sample, rad/s, body frame (BROAD only)
  std::vector<char> use;       // samples that are scored
  double rate_hz = 0.0;        // nominal (median) sample rate
};

// Loads every data set; the recorded ones in full from data_dir ($POSEFAIR_DATA or
// ../shared/data, benchmark_data.hpp). quick: the synthetic ones only, shorter. A recorded set
// with a missing file is skipped with a line on notes; throws std::runtime_error naming a file
// that is malformed, or, when no recorded file is there at all, every file and where it comes from.
std::vector<QualityDataset> load_quality_datasets(const std::filesystem::path& data_dir, bool quick, std::ostream& notes);

}  // namespace posefair::tools
