// TUM trajectories: `timestamp tx ty tz qx qy qz qw` per line (w last), `#` comments.
#include <limits>

#include "posefair/formats/format_detail.hpp"

namespace posefair::formats::detail {

PoseFile parse_tum(std::string text, const std::string& name, const ReadOptions& options) {
  auto doc = std::make_shared<Document>();
  doc->format = PoseFormat::Tum;
  doc->has_position = true;
  PoseSequence poses;
  double previous = -std::numeric_limits<double>::infinity();

  for (const Line& line : split_lines(text)) {
    const std::string_view content = trim(view(text, line.text));
    if (content.empty() || content.front() == '#') continue;
    const std::vector<Span> f = split_whitespace(text, line.text);
    if (f.size() != 8)
      throw PoseFileError(name, line.number,
                          "expected 8 fields (timestamp tx ty tz qx qy qz qw), found " +
                              std::to_string(f.size()));
    double v[8];
    for (std::size_t i = 0; i < 8; ++i)
      v[i] = finite_field(view(text, f[i]), FieldLabel{i + 1, {}, {}}, name, line.number);
    check_time_order(previous, v[0], name, line.number);
    previous = v[0];
    poses.time.push_back(v[0]);
    poses.position.emplace_back(v[1], v[2], v[3]);
    poses.orientation.push_back(
        unit_quaternion(v[7], v[4], v[5], v[6], options.unit_tolerance, name, line.number));
    doc->rows.push_back(PoseSpans{f[0], {f[7], f[4], f[5], f[6]}, {f[1], f[2], f[3]}});
  }
  if (poses.size() == 0)
    throw PoseFileError(name, 0, is_blank(text) ? "empty file" : "no samples");
  doc->text = std::move(text);
  return PoseFile(name, std::move(poses), std::move(doc));
}

namespace {

void append_tum_line(std::string& out, double t, const Vec3& p, const Quat& q) {
  const double v[8] = {t, p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()};
  for (int i = 0; i < 8; ++i) {
    if (i > 0) out += ' ';
    out += format_number(v[i]);
  }
  out += '\n';
}

}  // namespace

std::string render_tum(const PoseFile& original, const PoseSequence& poses) {
  const Document& doc = original.document();
  if (doc.fresh) {
    std::string out = doc.text;
    for (std::size_t k = 0; k < poses.size(); ++k)
      append_tum_line(out, poses.time[k], poses.has_position() ? poses.position[k] : Vec3::Zero(),
                      poses.orientation[k]);
    return out;
  }
  const PoseSequence& old = original.poses();
  std::vector<Edit> edits;
  append_pose_edits(doc, old, poses, edits);
  return apply_edits(doc.text, std::move(edits));
}

}  // namespace posefair::formats::detail
