#pragma once
// The operators' control socket protocol (docs/operations.md, "Control socket"): a client
// connects to posefaird's Unix socket, writes one request line and reads one JSON object back.
// The request is ASCII words separated by single spaces, ended by "\n", at most
// kMaxControlRequest bytes: `status`, `streams`, `subscribers`, `counters`, `reload`,
// `record start`, `record stop`.
//
// Pure: bytes in, a command out, never throws, never reads outside the span
// (tests/fuzz/control_command_fuzz.cpp).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace posefair::daemon {

inline constexpr std::size_t kMaxControlRequest = 256;

enum class ControlVerb : std::uint8_t { Status, Streams, Subscribers, Counters, Reload, RecordStart, RecordStop };

enum class ControlCommandError : std::uint8_t {
  None = 0,
  Empty,          // "empty"
  Oversized,      // "oversized"
  NoNewline,      // "no-newline": the line is not ended (or more follows it)
  BadCharacter,   // "bad-character": outside printable ASCII, or a double or edge space
  UnknownCommand, // "unknown-command"
};
std::string_view to_string(ControlCommandError e);
std::string_view to_string(ControlVerb v);  // the request text, e.g. "record start"
// Changes the daemon (logged with the peer's credentials).
bool changes_daemon(ControlVerb v);

struct ControlCommand {
  ControlCommandError error = ControlCommandError::None;
  ControlVerb verb = ControlVerb::Status;
  explicit operator bool() const { return error == ControlCommandError::None; }
};

ControlCommand parse_control_command(std::span<const std::uint8_t> request);

}  // namespace posefair::daemon
