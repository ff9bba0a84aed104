// can-utils candump log files: the parser and the writer of candump_log.hpp. The format is the
// one can-utils' lib.c defines (sprint_canframe writes it, parse_canframe reads it for
// canplayer and cansend); choices where it is loose:
// - Identifiers: exactly 3 hex digits (standard, at most 0x7FF) or 8 (extended; with the ERR
//   flag bit 0x20000000 set it is an error frame, as candump writes them, and the EFF flag is not
//   added). Upper or lower case hex everywhere.
// - Data: pairs of hex digits, a '.' allowed between bytes only; at most 8 bytes for classic
//   frames, 64 for FD, and an FD length must be one a DLC can give (0..8, 12, 16, 20, 24, 32, 48,
//   64). "_X" (raw DLC 9..F) is accepted after exactly 8 classic data bytes or after R8, and
//   otherwise dropped: decoders see 8 bytes.
// - The time "(s.ffffff)": digits, a '.', digits. Negative or missing times are errors.
// - After the frame only a direction token "T" or "R" may follow.
#include "posefair/formats/candump_log.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace posefair::formats {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view next_token(std::string_view& rest) {
  std::size_t i = 0;
  while (i < rest.size() && is_space(rest[i])) ++i;
  std::size_t j = i;
  while (j < rest.size() && !is_space(rest[j])) ++j;
  const std::string_view t = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return t;
}

// Hex data bytes with optional '.' between them, into f.data; false with `error` otherwise.
bool parse_data(std::string_view s, std::size_t max, CanFrame& f, std::string& error) {
  std::size_t n = 0;
  std::size_t i = 0;
  while (i < s.size()) {
    if (s[i] == '.' && n > 0 && i + 1 < s.size()) {
      ++i;
      continue;
    }
    if (i + 1 >= s.size() || hex_digit(s[i]) < 0 || hex_digit(s[i + 1]) < 0) {
      error = "bad data byte at \"" + std::string(s.substr(i)) + "\" (pairs of hex digits expected)";
      return false;
    }
    if (n == max) {
      error = "more than " + std::to_string(max) + " data bytes";
      return false;
    }
    f.data[n++] = static_cast<std::uint8_t>(hex_digit(s[i]) << 4 | hex_digit(s[i + 1]));
    i += 2;
  }
  f.len = static_cast<std::uint8_t>(n);
  return true;
}

// Splits off a "_X" raw DLC suffix; false with `error` when it is not a hex digit 9..F.
bool strip_raw_dlc(std::string_view& s, bool allowed, std::string& error) {
  const std::size_t u = s.find('_');
  if (u == std::string_view::npos) return true;
  const std::string_view dlc = s.substr(u + 1);
  if (!allowed || dlc.size() != 1 || hex_digit(dlc[0]) < 9) {
    error = "bad raw DLC suffix \"" + std::string(s.substr(u)) + "\" (only _9 .. _F after 8 bytes)";
    return false;
  }
  s = s.substr(0, u);
  return true;
}

}  // namespace

std::optional<CanFrame> parse_candump_frame(std::string_view token, std::string& error) {
  const std::size_t hash = token.find('#');
  if (hash == std::string_view::npos) {
    error = "no '#' in frame \"" + std::string(token) + "\"";
    return std::nullopt;
  }
  const std::string_view id_text = token.substr(0, hash);
  std::uint32_t id = 0;
  const auto [end, ec] = std::from_chars(id_text.data(), id_text.data() + id_text.size(), id, 16);
  if ((id_text.size() != 3 && id_text.size() != 8) || ec != std::errc() || end != id_text.data() + id_text.size()) {
    error = "identifier \"" + std::string(id_text) + "\" is not 3 or 8 hex digits";
    return std::nullopt;
  }
  CanFrame f;
  if (id_text.size() == 3) {
    if (id > CanFrame::kSffMask) {
      error = "standard identifier " + std::string(id_text) + " above 7FF";
      return std::nullopt;
    }
    f.can_id = id;
  } else if (id & CanFrame::kErrFlag) {
    if (id & (CanFrame::kEffFlag | CanFrame::kRtrFlag)) {
      error = "error frame identifier " + std::string(id_text) + " with EFF/RTR bits";
      return std::nullopt;
    }
    f.can_id = id;
  } else {
    if (id > CanFrame::kEffMask) {
      error = "extended identifier " + std::string(id_text) + " above 1FFFFFFF";
      return std::nullopt;
    }
    f.can_id = id | CanFrame::kEffFlag;
  }

  std::string_view body = token.substr(hash + 1);
  if (!body.empty() && body[0] == '#') {  // CAN FD
    if (body.size() < 2 || hex_digit(body[1]) < 0 || hex_digit(body[1]) > 0x7) {
      error = "CAN FD frame without a flags digit 0..7 after '##'";
      return std::nullopt;
    }
    f.fd = true;
    f.fd_flags = static_cast<std::uint8_t>(hex_digit(body[1]) | CanFrame::kFdFdf);
    if (f.error()) {
      error = "error frame in CAN FD form";
      return std::nullopt;
    }
    if (!parse_data(body.substr(2), CanFrame::kMaxFd, f, error)) return std::nullopt;
    if (!valid_fd_length(f.len)) {
      error = "CAN FD length " + std::to_string(f.len) + " is not one a DLC gives";
      return std::nullopt;
    }
    return f;
  }
  if (!body.empty() && (body[0] == 'R' || body[0] == 'r')) {
    if (f.error()) {
      error = "remote error frame";
      return std::nullopt;
    }
    body.remove_prefix(1);
    if (!strip_raw_dlc(body, body == "8" || body.substr(0, 2) == "8_", error)) return std::nullopt;
    f.can_id |= CanFrame::kRtrFlag;
    if (body.empty()) return f;
    if (body.size() != 1 || body[0] < '0' || body[0] > '8') {
      error = "remote frame length \"" + std::string(body) + "\" is not 0..8";
      return std::nullopt;
    }
    f.len = static_cast<std::uint8_t>(body[0] - '0');
    return f;
  }
  const std::size_t u = body.find('_');
  const bool eight = u != std::string_view::npos && parse_data(body.substr(0, u), CanFrame::kMaxClassic, f, error) && f.len == 8;
  if (!strip_raw_dlc(body, eight, error)) return std::nullopt;
  if (!parse_data(body, CanFrame::kMaxClassic, f, error)) return std::nullopt;
  return f;
}

CandumpLog parse_candump_log(std::string_view text) {
  CandumpLog log;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    ++log.lines;
    std::string_view rest = line;
    const std::string_view stamp = next_token(rest);
    if (stamp.empty()) continue;  // blank line
    const auto problem = [&](std::string message) { log.problems.push_back({log.lines, std::move(message)}); };
    if (stamp.size() < 3 || stamp.front() != '(' || stamp.back() != ')') {
      problem("expected \"(<time>) <interface> <frame>\", got \"" + std::string(line.substr(0, 80)) + "\"");
      continue;
    }
    const std::string_view digits = stamp.substr(1, stamp.size() - 2);
    const std::size_t dot = digits.find('.');
    double t = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), t, std::chars_format::fixed);
    if (dot == 0 || dot == std::string_view::npos || dot + 1 == digits.size() || ec != std::errc() ||
        end != digits.data() + digits.size() || digits.find_first_not_of("0123456789.") != std::string_view::npos) {
      problem("bad time \"" + std::string(stamp) + "\" (seconds.fraction expected)");
      continue;
    }
    const std::string_view interface = next_token(rest);
    const std::string_view frame = next_token(rest);
    const std::string_view direction = next_token(rest);
    const std::string_view extra = next_token(rest);
    if (interface.empty() || frame.empty()) {
      problem("missing interface or frame after the time");
      continue;
    }
    if (!extra.empty() || (!direction.empty() && direction != "T" && direction != "R")) {
      problem("unexpected \"" + std::string(direction) + "\" after the frame");
      continue;
    }
    std::string error;
    std::optional<CanFrame> f = parse_candump_frame(frame, error);
    if (!f) {
      problem(error);
      continue;
    }
    f->timestamp = t;
    log.records.push_back({*f, std::string(interface), log.lines});
  }
  return log;
}

CandumpLog read_candump_log(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CandumpFileError(path.string() + ": cannot open candump log");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw CandumpFileError(path.string() + ": read error");
  return parse_candump_log(text.str());
}

std::string format_candump_line(const CanFrame& f, std::string_view interface) {
  char buf[512];  // a time up to 1e308 s with 6 decimals fits
  std::snprintf(buf, sizeof buf, "(%.6f) ", f.timestamp);
  std::string out = buf;
  out += interface;
  out += ' ';
  if (f.error())
    std::snprintf(buf, sizeof buf, "%08X#", f.can_id & (CanFrame::kEffMask | CanFrame::kErrFlag));
  else if (f.extended())
    std::snprintf(buf, sizeof buf, "%08X#", f.id());
  else
    std::snprintf(buf, sizeof buf, "%03X#", f.id());
  out += buf;
  if (f.remote()) {
    out += 'R';
    if (f.len > 0) out += static_cast<char>('0' + (f.len > 8 ? 8 : f.len));
    return out;
  }
  if (f.fd) {
    std::snprintf(buf, sizeof buf, "#%X", f.fd_flags & (CanFrame::kFdBrs | CanFrame::kFdEsi));
    out += buf;
  }
  for (std::size_t i = 0; i < f.len; ++i) {
    std::snprintf(buf, sizeof buf, "%02X", f.data[i]);
    out += buf;
  }
  return out;
}

}  // namespace posefair::formats
