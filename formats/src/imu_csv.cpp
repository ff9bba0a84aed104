// BROAD-style raw IMU CSV (imu_csv.hpp): the pose CSV's text helpers, a column lookup by
// prefix and unit suffix, one Sample per row.
#include "posefair/formats/imu_csv.hpp"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "posefair/formats/format_detail.hpp"

namespace posefair::formats {

namespace {

using detail::Span;

// A sensor's three columns and the factor that turns their unit into SI (or µT).
struct Triple {
  std::array<std::size_t, 3> column{};
  double scale = 1.0;
};

struct UnitSuffix {
  std::string_view suffix;
  double scale;
};

// The x, y, z columns named <prefix><axis>[_unit] for one of `prefixes`; the unit of the x
// column decides the scale (all three must share it).
std::optional<Triple> find_triple(const std::vector<std::string>& names,
                                  std::initializer_list<std::string_view> prefixes,
                                  std::initializer_list<UnitSuffix> units, const std::string& file,
                                  std::size_t line) {
  for (std::string_view prefix : prefixes) {
    std::array<std::optional<std::size_t>, 3> found;
    std::array<std::string_view, 3> rest;
    for (std::size_t i = 0; i < names.size(); ++i) {
      const std::string_view n = names[i];
      if (n.size() <= prefix.size() || n.substr(0, prefix.size()) != prefix) continue;
      const char axis = n[prefix.size()];
      if (axis < 'x' || axis > 'z') continue;
      const std::string_view tail = n.substr(prefix.size() + 1);
      if (!tail.empty() && tail.front() != '_') continue;
      auto& slot = found[static_cast<std::size_t>(axis - 'x')];
      if (slot) throw PoseFileError(file, line, "duplicate column '" + names[i] + "'");
      slot = i;
      rest[static_cast<std::size_t>(axis - 'x')] = tail;
    }
    if (!found[0] && !found[1] && !found[2]) continue;
    if (!found[0] || !found[1] || !found[2])
      throw PoseFileError(file, line,
                          "incomplete column set " + std::string(prefix) + "x/y/z: need all three");
    if (rest[0] != rest[1] || rest[0] != rest[2])
      throw PoseFileError(file, line,
                          "columns " + std::string(prefix) + "x/y/z have different units");
    Triple t{{*found[0], *found[1], *found[2]}, 1.0};
    bool known = rest[0].empty();
    for (const UnitSuffix& u : units)
      if (rest[0] == u.suffix) {
        t.scale = u.scale;
        known = true;
      }
    if (!known)
      throw PoseFileError(file, line,
                          "unknown unit '" + std::string(rest[0].substr(1)) + "' in column " +
                              names[*found[0]]);
    return t;
  }
  return std::nullopt;
}

std::optional<std::size_t> find_column(const std::vector<std::string>& names,
                                       std::initializer_list<std::string_view> wanted) {
  for (std::string_view w : wanted)
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == w) return i;
  return std::nullopt;
}

// NaN for `nan` and empty fields (a missing reading), the value for a number; throws otherwise.
double reading(std::string_view text, Span field, std::size_t column, const std::string& header,
               const std::string& file, std::size_t line) {
  const std::string_view s = detail::trim(detail::view(text, field));
  if (s.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::optional<double> v = detail::parse_number(s);
  if (!v || std::isinf(*v))
    throw PoseFileError(file, line,
                        detail::FieldLabel{column + 1, header, {}}.str() + " '" + std::string(s) +
                            "' is not a number");
  return *v;
}

}  // namespace

ImuRecording parse_imu_csv(const std::string& text, const std::string& name) {
  const std::vector<detail::Line> lines = detail::split_lines(text);
  auto line = lines.begin();
  while (line != lines.end() && detail::is_blank(detail::view(text, line->text))) ++line;
  if (line == lines.end()) throw PoseFileError(name, 0, "empty file");

  std::vector<std::string> names;
  for (const Span& s : detail::split_commas(text, line->text)) {
    std::string n = detail::lower(detail::view(text, s));
    if (n.size() >= 2 && n.front() == '"' && n.back() == '"') n = n.substr(1, n.size() - 2);
    names.push_back(n);
  }
  const std::size_t header_line = line->number;
  const auto time = find_column(names, {"t_s", "t", "time", "timestamp"});
  const auto gyro = find_triple(names, {"gyr_", "gyro_"}, {{"_rads", 1.0}, {"_dps", M_PI / 180.0}},
                                name, header_line);
  const auto accel = find_triple(names, {"acc_", "accel_"}, {{"_ms2", 1.0}, {"_g", 9.80665}},
                                 name, header_line);
  const auto mag = find_triple(names, {"mag_"}, {{"_ut", 1.0}, {"_nt", 1e-3}, {"_gauss", 100.0}},
                               name, header_line);
  std::array<std::optional<std::size_t>, 4> quat;
  for (std::string_view prefix : {"gt_", ""}) {
    for (std::size_t c = 0; c < 4; ++c)
      quat[c] = find_column(names, {std::string(prefix) + "q" + "wxyz"[c]});
    if (quat[0] && quat[1] && quat[2] && quat[3]) break;
  }
  const bool has_reference = quat[0] && quat[1] && quat[2] && quat[3];
  const auto movement = find_column(names, {"movement"});
  if (!time || !gyro || !accel)
    throw PoseFileError(name, header_line,
                        "missing columns: an IMU CSV needs a time column (t_s, t, time or "
                        "timestamp), gyroscope gyr_x/y/z and accelerometer acc_x/y/z");

  ImuRecording rec;
  rec.has_mag_column = mag.has_value();
  rec.has_reference_column = has_reference;
  double previous = -std::numeric_limits<double>::infinity();
  std::uint64_t sequence = 0;
  for (++line; line != lines.end(); ++line) {
    if (detail::is_blank(detail::view(text, line->text))) continue;
    const std::vector<Span> f = detail::split_commas(text, line->text);
    if (f.size() != names.size())
      throw PoseFileError(name, line->number,
                          "expected " + std::to_string(names.size()) +
                              " fields as in the header, found " + std::to_string(f.size()));
    const auto value = [&](std::size_t c) {
      return reading(text, f[c], c, names[c], name, line->number);
    };
    Sample s;
    s.sequence = sequence++;
    s.time = detail::finite_field(detail::view(text, f[*time]), {*time + 1, names[*time], {}}, name,
                                  line->number);
    detail::check_time_order(previous, s.time, name, line->number);
    previous = s.time;
    s.device_time = s.time;
    s.flags = kHasDeviceTime;
    const auto take = [&](const std::optional<Triple>& t, Vec3& out, std::uint32_t flag) {
      if (!t) return;
      for (int i = 0; i < 3; ++i) out[i] = value(t->column[static_cast<std::size_t>(i)]) * t->scale;
      if (out.allFinite()) {
        s.flags |= flag;
      } else {
        out.setZero();
        ++rec.missing_readings;
      }
    };
    take(gyro, s.gyro, kHasGyro);
    take(accel, s.accel, kHasAccel);
    take(mag, s.mag, kHasMag);
    s.flags |= kNoOrientation;
    if (has_reference) {
      const Quat q(value(*quat[0]), value(*quat[1]), value(*quat[2]), value(*quat[3]));
      if (q.coeffs().allFinite() && q.norm() > 0.5) {
        s.orientation = q.normalized();
        s.flags &= ~static_cast<std::uint32_t>(kNoOrientation);
      }
    }
    std::uint8_t moving = 1;
    if (movement) {
      const double m = value(*movement);
      moving = (std::isfinite(m) && m != 0.0) ? 1 : 0;
    }
    rec.samples.push_back(s);
    rec.movement.push_back(moving);
  }
  if (rec.samples.empty()) throw PoseFileError(name, 0, "no samples");
  return rec;
}

ImuRecording read_imu_csv(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw PoseFileError(name, 0, "cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PoseFileError(name, 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_imu_csv(text.str(), name);
}

}  // namespace posefair::formats
