// Raw IMU recordings from CSV or a sample log stream (imu_recording_file.hpp).
#include "posefair/formats/imu_recording_file.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <optional>

#include "posefair/core/error.hpp"

namespace posefair::formats {

namespace {

constexpr std::uint32_t kRawFlags = kHasGyro | kHasAccel | kHasMag;

bool is_raw(const Sample& s) { return (s.flags & kRawFlags) != 0; }

// What the log holds per stream id: its name from the header (empty for an id the header
// lacks) and how many of its samples are raw.
struct StreamSummary {
  std::string name;
  std::uint64_t samples = 0;
  std::uint64_t raw = 0;
};

std::map<std::uint32_t, StreamSummary> summarise(const SampleLogContents& log) {
  std::map<std::uint32_t, StreamSummary> streams;
  for (const StreamInfo& info : log.header.streams) streams[info.id].name = info.name;
  for (const Sample& s : log.samples) {
    StreamSummary& summary = streams[s.stream_id];
    ++summary.samples;
    if (is_raw(s)) ++summary.raw;
  }
  return streams;
}

// "'head' (id 1)", or "(unnamed) (id 9)" for an id the header does not name.
std::string stream_label(std::uint32_t id, const std::string& name) {
  // Appended piecewise: GCC 12's -Wrestrict misfires on "'" + name + "'".
  std::string label;
  if (name.empty()) {
    label = "(unnamed)";
  } else {
    label.push_back('\'');
    label.append(name);
    label.push_back('\'');
  }
  label.append(" (id ").append(std::to_string(id)).append(")");
  return label;
}

// "'head' (id 1): 0 raw samples of 400; 'imu' (id 2): 800 raw samples of 800"
std::string list_streams(const std::map<std::uint32_t, StreamSummary>& streams) {
  if (streams.empty()) return "none";
  std::string text;
  for (const auto& [id, s] : streams) {
    if (!text.empty()) text += "; ";
    text += stream_label(id, s.name) + ": " + std::to_string(s.raw) + " raw samples of " + std::to_string(s.samples);
  }
  return text;
}

// The id `stream` names: a stream name first, then a decimal id.
std::optional<std::uint32_t> find_stream(const std::map<std::uint32_t, StreamSummary>& streams,
                                         std::string_view stream) {
  for (const auto& [id, s] : streams)
    if (s.name == stream) return id;
  std::uint32_t id = 0;
  const auto [end, ec] = std::from_chars(stream.data(), stream.data() + stream.size(), id);
  if (ec == std::errc() && end == stream.data() + stream.size() && streams.count(id) != 0) return id;
  return std::nullopt;
}

}  // namespace

ImuRecording imu_recording_from_sample_log(const SampleLogContents& log, std::string_view stream,
                                           const std::string& name) {
  const std::map<std::uint32_t, StreamSummary> streams = summarise(log);
  std::optional<std::uint32_t> chosen;
  if (stream.empty()) {
    for (const auto& [id, s] : streams) {
      if (s.raw == 0) continue;
      if (chosen)
        throw Error(ErrorKind::Usage, name + ": several streams have raw inertial samples; choose one with --stream: " +
                                          list_streams(streams),
                    "stream");
      chosen = id;
    }
    if (!chosen)
      throw Error(ErrorKind::DataErr,
                  name + ": no stream has raw inertial samples (gyroscope, accelerometer or magnetometer); streams: " +
                      list_streams(streams));
  } else {
    chosen = find_stream(streams, stream);
    if (!chosen)
      throw Error(ErrorKind::Usage,
                  name + ": no stream '" + std::string(stream) + "' in this log; streams: " + list_streams(streams),
                  "stream");
    if (streams.at(*chosen).raw == 0)
      throw Error(ErrorKind::DataErr,
                  name + ": stream " + stream_label(*chosen, streams.at(*chosen).name) +
                      " has no raw inertial samples (gyroscope, accelerometer or magnetometer); streams: " +
                      list_streams(streams));
  }

  ImuRecording out;
  out.samples.reserve(streams.at(*chosen).raw);
  for (const Sample& s : log.samples) {
    if (s.stream_id != *chosen || !is_raw(s)) continue;
    out.samples.push_back(s);
    out.has_mag_column = out.has_mag_column || s.has_mag();
    out.has_reference_column = out.has_reference_column || s.has_orientation();
  }
  out.movement.assign(out.samples.size(), 1);
  return out;
}

ImuRecordingFile read_imu_recording_file(const std::filesystem::path& path, std::string_view stream) {
  ImuRecordingFile file;
  if (!is_sample_log_file(path)) {
    if (!stream.empty())
      throw Error(ErrorKind::Usage, path.string() + ": --stream applies to a sample log; this is read as CSV",
                  "stream");
    file.recording = read_imu_csv(path);
    return file;
  }
  SampleLogContents log = read_sample_log_set(path);
  file.from_sample_log = true;
  file.recording = imu_recording_from_sample_log(log, stream, path.string());
  const std::uint32_t id = file.recording.samples.front().stream_id;
  const StreamInfo* info = log.header.find(id);
  file.stream = stream_label(id, info != nullptr ? info->name : std::string());
  file.damage = std::move(log.stats.problems);
  return file;
}

}  // namespace posefair::formats
