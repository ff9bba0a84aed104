#include "camera_keyframe_file.hpp"

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <Eigen/LU>

namespace posefair::tools {
namespace {

struct LineReader {
  std::istringstream in;
  std::string where;

  [[noreturn]] void fail(const std::string& what) const { throw KeyframeFileError(where + ": " + what); }

  double number(const char* what) {
    std::string tok;
    if (!(in >> tok)) fail(std::string("missing ") + what);
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0' || !std::isfinite(v)) fail(std::string("bad ") + what + " '" + tok + "'");
    return v;
  }
  Eigen::Vector3d vec3(const char* what) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = number(what);
    return v;
  }
};

void check_lens(const LineReader& r, const CameraIntrinsics& l) {
  if (!(l.fov_y > 0.0 && l.fov_y < std::numbers::pi)) r.fail("fov must be in (0, 180) degrees");
  if (!(l.aspect > 0.0)) r.fail("aspect must be positive (P_b would have no real logarithm)");
  if (!(l.near > 0.0 && l.far > l.near)) r.fail("need 0 < near < far");
}

}  // namespace

std::vector<CameraKeyframe> read_camera_keyframes(const std::filesystem::path& path) {
  std::ifstream f(path);
  if (!f) throw std::ios_base::failure("cannot open " + path.string());
  std::vector<CameraKeyframe> keys;
  std::string text;
  for (int line = 1; std::getline(f, text); ++line) {
    if (const auto hash = text.find('#'); hash != std::string::npos) text.erase(hash);
    LineReader r{std::istringstream(text), path.string() + ":" + std::to_string(line)};
    std::string word;
    if (!(r.in >> word)) continue;  // blank or comment
    if (word != "key") r.fail("expected 'key', found '" + word + "'");
    const double time = r.number("time");
    if (!keys.empty() && !(time > keys.back().time))
      r.fail("keyframe times must increase (previous key at line " + std::to_string(keys.back().line) + ")");
    CameraParams c;
    c.lens.fov_y = 45.0 * std::numbers::pi / 180.0;
    bool has_from = false, has_at = false, has_matrix = false;
    Mat4 m = Mat4::Zero();
    while (r.in >> word) {
      if (word == "from") has_from = true, c.from = r.vec3("from coordinate");
      else if (word == "at") has_at = true, c.at = r.vec3("at coordinate");
      else if (word == "up") c.up = r.vec3("up coordinate");
      else if (word == "fov") c.lens.fov_y = r.number("fov") * std::numbers::pi / 180.0;
      else if (word == "aspect") c.lens.aspect = r.number("aspect");
      else if (word == "skew") c.lens.skew = r.number("skew");
      else if (word == "cop") c.lens.cop_u = r.number("cop u"), c.lens.cop_v = r.number("cop v");
      else if (word == "near") c.lens.near = r.number("near");
      else if (word == "far") c.lens.far = r.number("far");
      else if (word == "matrix") {
        has_matrix = true;
        for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = r.number("matrix entry");
      } else
        r.fail("unknown field '" + word + "'");
    }
    check_lens(r, c.lens);
    CameraKey key;
    if (has_matrix) {
      if (has_from || has_at) r.fail("give either a matrix or from/at, not both");
      if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12)
        r.fail("the matrix must be affine (bottom row 0 0 0 1): give P_b S R T without the perspective part P_a");
      if (!(std::abs(m.topLeftCorner<3, 3>().determinant()) > 1e-12 * std::pow(m.topLeftCorner<3, 3>().norm(), 3)))
        r.fail("the matrix is singular");
      if (m.topLeftCorner<3, 3>().determinant() < 0.0) r.fail("the matrix mirrors (negative determinant): no real logarithm");
      key = camera_key(m, c.lens.near / c.lens.far);
    } else {
      if (!has_from || !has_at) r.fail("a keyframe needs 'from X Y Z' and 'at X Y Z' (or 'matrix' and 16 numbers)");
      try {
        key = camera_key(c);
      } catch (const std::invalid_argument& e) {
        r.fail(e.what());
      }
    }
    keys.push_back({time, key, line});
  }
  if (keys.empty()) throw KeyframeFileError(path.string() + ": no keyframes");
  return keys;
}

}  // namespace posefair::tools
