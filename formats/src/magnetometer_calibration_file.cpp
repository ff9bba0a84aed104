// The magnetometer calibration text file (magnetometer_calibration_file.hpp).
#include "posefair/formats/magnetometer_calibration_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "posefair/formats/format_detail.hpp"

namespace posefair::formats {

std::string render_magnetometer_calibration(const MagnetometerCalibration& c) {
  std::string out = "# posefair magnetometer calibration: corrected = soft_iron * (raw - offset)\noffset";
  for (int i = 0; i < 3; ++i) {
    out += ' ';
    out += detail::format_number(c.offset[i]);
  }
  out += "\nsoft_iron";
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      out += detail::format_number(c.soft_iron(r, k));
    }
  out += "\nfield_strength " + detail::format_number(c.field_strength);
  out += "\nresidual_rms " + detail::format_number(c.residual_rms) + "\n";
  return out;
}

MagnetometerCalibration parse_magnetometer_calibration(const std::string& text, const std::string& name) {
  MagnetometerCalibration c;
  bool offset = false, soft_iron = false;
  for (const detail::Line& line : detail::split_lines(text)) {
    const std::string_view l = detail::trim(detail::view(text, line.text));
    if (l.empty() || l.front() == '#') continue;
    const std::vector<detail::Span> f = detail::split_whitespace(text, line.text);
    const std::string key(detail::view(text, f[0]));
    const std::size_t want = key == "offset" ? 3 : key == "soft_iron" ? 9 : key == "field_strength" || key == "residual_rms" ? 1 : 0;
    if (want == 0) throw PoseFileError(name, line.number, "unknown key '" + key + "'");
    if (f.size() != want + 1)
      throw PoseFileError(name, line.number, key + " takes " + std::to_string(want) + " numbers, found " +
                                                 std::to_string(f.size() - 1));
    double v[9];
    for (std::size_t i = 0; i < want; ++i)
      v[i] = detail::finite_field(detail::view(text, f[i + 1]), {i + 2, key, {}}, name, line.number);
    if (key == "offset") {
      c.offset = Vec3(v[0], v[1], v[2]);
      offset = true;
    } else if (key == "soft_iron") {
      for (int i = 0; i < 9; ++i) c.soft_iron(i / 3, i % 3) = v[i];
      soft_iron = true;
    } else if (key == "field_strength") {
      c.field_strength = v[0];
    } else {
      c.residual_rms = v[0];
    }
  }
  if (!offset || !soft_iron) throw PoseFileError(name, 0, "a calibration needs both offset and soft_iron lines");
  return c;
}

MagnetometerCalibration read_magnetometer_calibration(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PoseFileError(path.string(), 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_magnetometer_calibration(text.str(), path.string());
}

}  // namespace posefair::formats
