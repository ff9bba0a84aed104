#pragma once
// A raw inertial recording from either file posefair keeps one in (posefair fuse, posefair
// calibrate): a BROAD-style CSV (imu_csv.hpp) or one stream of a sample log (sample_log.hpp,
// what posefaird's recorder writes). Both become the same ImuRecording, so everything after
// the reading is one path.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/formats/imu_csv.hpp"
#include "posefair/formats/sample_log.hpp"

namespace posefair::formats {

// The samples of one stream of a log that carry a raw reading (kHasGyro, kHasAccel or kHasMag),
// in file order: time = the sample's time (the one posefaird's fusion stage steps by), the
// orientation kept when the sample has one (a reference, as the CSV's gt_q columns). movement
// is all 1.
//
// `stream` is a stream's name or its id in decimal; empty: the one stream that has raw samples.
// Throws posefair::Error naming the streams present ("name (id N, M raw samples)"):
//   ErrorKind::Usage    `stream` is empty and several streams have raw samples, or it names
//                       no stream of the log;
//   ErrorKind::DataErr  the chosen stream (or, with `stream` empty, every stream) has no raw
//                       samples.
// `name` (the file's path) starts every message.
ImuRecording imu_recording_from_sample_log(const SampleLogContents& log, std::string_view stream,
                                           const std::string& name);

struct ImuRecordingFile {
  ImuRecording recording;
  bool from_sample_log = false;
  std::string stream;                     // the log stream read: "name (id N)"; empty for CSV
  std::vector<SampleLogProblem> damage;   // a log's unreadable tails (what was before them is read)
};

// The recording of `path`: a sample log (and its rotated parts) by imu_recording_from_sample_log,
// (is_sample_log_file), anything else by read_imu_csv. Throws what those throw (PoseFileError, SampleLogError,
// posefair::Error); a non-empty `stream` for a CSV is posefair::Error(Usage).
ImuRecordingFile read_imu_recording_file(const std::filesystem::path& path, std::string_view stream);

}  // namespace posefair::formats
