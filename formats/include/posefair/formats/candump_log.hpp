#pragma once
// can-utils candump log files (`candump -l`, `candump -L`; what canplayer replays): one frame
// per line, "(<seconds>.<fraction>) <interface> <frame>", the frame in can-utils' compact form:
//   123#11223344          standard id (3 hex digits), 0..8 data bytes in hex
//   12345678#1122         extended id (8 hex digits)
//   123#11.22.33          bytes may be separated by dots
//   123#R   123#R5        remote frame, optionally with its length
//   123#1122334455667788_E  classic frame with a raw DLC 9..15 (len8_dlc), kept as 8 bytes
//   123##1AABB            CAN FD: '##', one hex digit of FD flags (BRS 1, ESI 2), then 0..64 bytes
//   20000004#0004000000000000  error frame (the ERR flag 0x20000000 in an 8-digit id)
// A line may end with a direction token "T" or "R" (newer candump with -x). Parsing never
// throws on content: a malformed line is reported with its number and skipped, so a damaged
// log still replays what it holds. Reference: can-utils lib.c/lib.h (parse_canframe,
// sprint_canframe) and candump.c, which define the format.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/formats/can_frame.hpp"

namespace posefair::formats {

struct CandumpRecord {
  CanFrame frame;         // frame.timestamp: the line's time, seconds
  std::string interface;  // e.g. "can0"
  std::size_t line = 0;   // 1-based
};

struct CandumpProblem {
  std::size_t line = 0;  // 1-based
  std::string message;   // what is wrong with it
};

struct CandumpLog {
  std::vector<CandumpRecord> records;    // the good lines, in file order
  std::vector<CandumpProblem> problems;  // the malformed lines (skipped)
  std::size_t lines = 0;                 // lines read (blank ones included)
};

// The file could not be read at all (missing, unreadable).
class CandumpFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses a whole log held in memory. Blank lines are skipped without a problem.
CandumpLog parse_candump_log(std::string_view text);
// Reads and parses a file. Throws CandumpFileError when it cannot be opened or read.
CandumpLog read_candump_log(const std::filesystem::path& path);

// One frame in compact form ("123#1122"); nullopt with `error` set when it is not one.
std::optional<CanFrame> parse_candump_frame(std::string_view token, std::string& error);
// The line `candump -l` writes for `frame` (no newline): "(%.6f) <interface> <frame>".
std::string format_candump_line(const CanFrame& frame, std::string_view interface);

}  // namespace posefair::formats
