#include "keyframe_file.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::tools {
namespace {

using formats::PoseFileError;

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',' || c == ' ' || c == '\t' || c == '\r') {
      if (!cur.empty()) out.push_back(std::move(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(std::move(cur));
  return out;
}

double number(const std::string& field, const std::string& name, std::size_t line) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  if (end == field.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw PoseFileError(name, line, "'" + field + "' is not a finite number");
  return v;
}

std::string format(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

}  // namespace

SplineKeyframes parse_keyframes(std::istream& in, const std::string& name) {
  SplineKeyframes keys;
  std::string text;
  std::size_t line_no = 0, layout = 0, last_line = 0;
  while (std::getline(in, text)) {
    ++line_no;
    const std::vector<std::string> f = split_fields(text);
    if (f.empty() || f[0][0] == '#') continue;
    last_line = line_no;
    if (f[0] == "omega_start" || f[0] == "omega_end") {
      if (f.size() != 4) throw PoseFileError(name, line_no, f[0] + " needs three values wx wy wz (rad/s)");
      const Vec3 w(number(f[1], name, line_no), number(f[2], name, line_no), number(f[3], name, line_no));
      auto& slot = f[0] == "omega_start" ? keys.omega_start : keys.omega_end;
      if (slot) throw PoseFileError(name, line_no, f[0] + " given twice");
      slot = w;
      continue;
    }
    if (f.size() != 5 && f.size() != 8)
      throw PoseFileError(name, line_no, "expected 5 fields (t w x y z) or 8 (TUM: t tx ty tz qx qy qz qw), got " +
                                             std::to_string(f.size()));
    if (layout == 0) layout = f.size();
    if (f.size() != layout)
      throw PoseFileError(name, line_no, "this keyframe has " + std::to_string(f.size()) + " fields, earlier ones " +
                                             std::to_string(layout) + ": use one layout per file");
    std::vector<double> v;
    for (const std::string& s : f) v.push_back(number(s, name, line_no));
    const Quat q = layout == 5 ? Quat(v[1], v[2], v[3], v[4]) : Quat(v[7], v[4], v[5], v[6]);
    const double t = v[0];
    if (!keys.time.empty() && !(t > keys.time.back()))
      throw PoseFileError(name, line_no, "time " + format(t) + " does not increase (previous keyframe at " +
                                             format(keys.time.back()) + ")");
    if (std::abs(q.norm() - 1.0) > kKeyframeUnitTolerance)
      throw PoseFileError(name, line_no, "non-unit quaternion: |q| = " + format(q.norm()) + " (tolerance " +
                                             format(kKeyframeUnitTolerance) + ")");
    keys.time.push_back(t);
    keys.orientation.push_back(q.normalized());
  }
  if (keys.time.size() < 2)
    throw PoseFileError(name, last_line, "fewer than two keyframes (found " + std::to_string(keys.time.size()) + ")");
  return keys;
}

SplineKeyframes read_keyframes(const std::filesystem::path& path) {
  std::ifstream in(path);
  // An unreadable file is NoInput, not a malformed one: the message as PoseFileError words it.
  if (!in)
    throw Error(ErrorKind::NoInput, PoseFileError(path.string(), 0, std::string("cannot open: ") + std::strerror(errno)).what());
  return parse_keyframes(in, path.string());
}

}  // namespace posefair::tools
