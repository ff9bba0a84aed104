#pragma once
// A golden replay log (tests/replay/README.md): a text header of "# key: value" lines ending
// with "# data:", then the device's raw bytes. Read by the replay check, written by the log maker.
#include <filesystem>
#include <map>
#include <string>

namespace posefair::replay {

struct ReplayLog {
  std::map<std::string, std::string> header;  // device, protocol, baud, rate, source, made, faults, option.<key>
  std::string data;                           // the raw bytes as the device sent them
};

// Throws std::runtime_error naming the file (and line) when it cannot be read or has no
// "# data:" line.
ReplayLog read_replay_log(const std::filesystem::path& path);

}  // namespace posefair::replay
