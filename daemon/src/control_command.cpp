#include "posefair/daemon/control_command.hpp"

#include <array>
#include <utility>

namespace posefair::daemon {
namespace {
constexpr std::array<std::pair<std::string_view, ControlVerb>, 7> kVerbs = {{
    {"status", ControlVerb::Status},
    {"streams", ControlVerb::Streams},
    {"subscribers", ControlVerb::Subscribers},
    {"counters", ControlVerb::Counters},
    {"reload", ControlVerb::Reload},
    {"record start", ControlVerb::RecordStart},
    {"record stop", ControlVerb::RecordStop},
}};
}  // namespace

std::string_view to_string(ControlCommandError e) {
  switch (e) {
    case ControlCommandError::None: return "ok";
    case ControlCommandError::Empty: return "empty";
    case ControlCommandError::Oversized: return "oversized";
    case ControlCommandError::NoNewline: return "no-newline";
    case ControlCommandError::BadCharacter: return "bad-character";
    case ControlCommandError::UnknownCommand: return "unknown-command";
  }
  return "unknown";
}

std::string_view to_string(ControlVerb v) {
  for (const auto& [text, verb] : kVerbs)
    if (verb == v) return text;
  return "unknown";
}

bool changes_daemon(ControlVerb v) {
  return v == ControlVerb::Reload || v == ControlVerb::RecordStart || v == ControlVerb::RecordStop;
}

ControlCommand parse_control_command(std::span<const std::uint8_t> request) {
  ControlCommand c;
  auto fail = [&](ControlCommandError e) {
    c.error = e;
    return c;
  };
  if (request.empty()) return fail(ControlCommandError::Empty);
  if (request.size() > kMaxControlRequest) return fail(ControlCommandError::Oversized);
  if (request.back() != '\n') return fail(ControlCommandError::NoNewline);
  const std::span<const std::uint8_t> line = request.first(request.size() - 1);
  if (line.empty()) return fail(ControlCommandError::Empty);
  for (std::size_t i = 0; i < line.size(); ++i) {
    const std::uint8_t b = line[i];
    if (b == '\n') return fail(ControlCommandError::NoNewline);
    if (b < 0x20 || b > 0x7e) return fail(ControlCommandError::BadCharacter);
    if (b == ' ' && (i == 0 || i + 1 == line.size() || line[i - 1] == ' ')) return fail(ControlCommandError::BadCharacter);
  }
  const std::string_view text(reinterpret_cast<const char*>(line.data()), line.size());
  for (const auto& [name, verb] : kVerbs) {
    if (name == text) {
      c.verb = verb;
      return c;
    }
  }
  return fail(ControlCommandError::UnknownCommand);
}

}  // namespace posefair::daemon
