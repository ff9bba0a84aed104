// Line and field splitting, strict number parsing and round-trip number formatting, and the
// value checks every reader shares.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "posefair/formats/format_detail.hpp"

namespace posefair::formats::detail {

namespace {
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
}  // namespace

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

bool is_blank(std::string_view s) { return trim(s).empty(); }

std::vector<Line> split_lines(std::string_view text) {
  std::vector<Line> lines;
  std::size_t begin = 0;
  std::size_t number = 1;
  while (begin < text.size()) {
    const std::size_t nl = text.find('\n', begin);
    const std::size_t end = nl == std::string_view::npos ? text.size() : nl;
    const std::size_t next = nl == std::string_view::npos ? text.size() : nl + 1;
    std::size_t content_end = end;
    if (content_end > begin && text[content_end - 1] == '\r') --content_end;
    // A UTF-8 byte order mark is not part of the first line's content (it stays in the file).
    const std::size_t content_begin =
        (begin == 0 && text.substr(0, 3) == "\xEF\xBB\xBF") ? std::min<std::size_t>(3, content_end) : begin;
    lines.push_back(Line{number, Span{content_begin, content_end - content_begin},
                         Span{begin, next - begin}});
    begin = next;
    ++number;
  }
  return lines;
}

std::vector<Span> split_whitespace(std::string_view text, Span line) {
  std::vector<Span> fields;
  std::size_t i = line.begin;
  const std::size_t end = line.end();
  while (i < end) {
    while (i < end && is_space(text[i])) ++i;
    if (i == end) break;
    const std::size_t start = i;
    while (i < end && !is_space(text[i])) ++i;
    fields.push_back(Span{start, i - start});
  }
  return fields;
}

std::vector<Span> split_commas(std::string_view text, Span line) {
  std::vector<Span> fields;
  std::size_t start = line.begin;
  bool quoted = false;
  const auto push = [&](std::size_t stop) {
    std::size_t b = start;
    std::size_t e = stop;
    while (b < e && is_space(text[b])) ++b;
    while (e > b && is_space(text[e - 1])) --e;
    fields.push_back(Span{b, e - b});
  };
  for (std::size_t i = line.begin; i < line.end(); ++i) {
    const char c = text[i];
    if (c == '"') {
      quoted = !quoted;  // "" inside a quoted field toggles twice: still quoted
    } else if (c == ',' && !quoted) {
      push(i);
      start = i + 1;
    }
  }
  push(line.end());
  return fields;
}

std::optional<double> parse_number(std::string_view field) {
  std::string_view s = trim(field);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trim(s.substr(1, s.size() - 2));
  if (!s.empty() && s.front() == '+') {
    s.remove_prefix(1);
    if (s.empty() || s.front() == '-' || s.front() == '+') return std::nullopt;
  }
  if (s.empty()) return std::nullopt;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  // Out-of-range magnitudes (1e999) are reported as result_out_of_range: not a usable number.
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::string format_number(double v) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  return std::string(buffer, result.ptr);
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::string FieldLabel::str() const {
  if (!text.empty()) return std::string(text);
  std::string out = "field " + std::to_string(number);
  if (!column.empty()) out += " (" + std::string(column) + ")";
  return out;
}

double finite_field(std::string_view field, const FieldLabel& label, const std::string& name,
                    std::size_t line) {
  const std::optional<double> v = parse_number(field);
  if (v && std::isfinite(*v)) return *v;
  const std::string shown(trim(field));
  throw PoseFileError(name, line,
                      label.str() + " '" + shown + (v ? "' is not finite" : "' is not a number"));
}

Quat unit_quaternion(double w, double x, double y, double z, double tolerance,
                     const std::string& name, std::size_t line) {
  Quat q(w, x, y, z);
  const double n2 = q.squaredNorm();
  if (!std::isfinite(n2)) throw PoseFileError(name, line, "quaternion is not finite");
  if (n2 == 0.0) throw PoseFileError(name, line, "zero quaternion");
  const double n = std::sqrt(n2);
  if (!(std::abs(n - 1.0) <= tolerance))
    throw PoseFileError(name, line,
                        "non-unit quaternion: norm " + format_number(n) +
                            " differs from 1 by more than the tolerance " + format_number(tolerance));
  // A quaternion that is already unit to rounding is kept exactly, so a file written from
  // normalised values reads back bit for bit (normalising twice can move the last bit).
  if (std::abs(n2 - 1.0) > 4e-15) q.coeffs() /= n;
  return q;
}

void check_time_order(double previous, double t, const std::string& name, std::size_t line) {
  if (t < previous)
    throw PoseFileError(name, line,
                        "time goes backwards: " + format_number(t) + " after " + format_number(previous));
}

}  // namespace posefair::formats::detail
