// BVH motion capture: HIERARCHY (joints and their channels) and MOTION (one row of channel
// values per frame). One joint's channels become the pose sequence; writing replaces only
// those values (and the Frames: count) in the original document.
#include <cmath>

#include "posefair/formats/format_detail.hpp"

namespace posefair::formats::detail {

namespace {

struct Token {
  std::string_view text;
  std::size_t line = 0;
};

bool keyword(const Token& t, std::string_view word) { return lower(t.text) == lower(word); }

class HierarchyParser {
 public:
  HierarchyParser(std::vector<Token> tokens, const std::string& name, std::size_t end_line)
      : tokens_(std::move(tokens)), name_(name), end_line_(end_line) {}

  void parse(Document& doc) {
    expect("HIERARCHY");
    if (at_end() || !keyword(peek(), "ROOT"))
      fail(at_end() ? end_line_ : peek().line, "expected ROOT");
    while (!at_end()) {
      const Token& t = next();
      if (!keyword(t, "ROOT")) fail(t.line, "expected ROOT, found '" + std::string(t.text) + "'");
      joint(doc, t.line);
    }
  }

 private:
  [[noreturn]] void fail(std::size_t line, const std::string& message) const {
    throw PoseFileError(name_, line, message);
  }
  bool at_end() const { return pos_ >= tokens_.size(); }
  const Token& peek() const { return tokens_[pos_]; }
  const Token& next() {
    if (at_end()) fail(end_line_, "unexpected end of HIERARCHY (missing '}' or MOTION?)");
    return tokens_[pos_++];
  }
  void expect(std::string_view word) {
    const std::size_t line = at_end() ? end_line_ : peek().line;
    const Token& t = next();
    if (!keyword(t, word))
      fail(line, "expected '" + std::string(word) + "', found '" + std::string(t.text) + "'");
  }
  void offset() {
    for (int i = 0; i < 3; ++i) {
      const Token& t = next();
      finite_field(t.text, FieldLabel{0, {}, "OFFSET value"}, name_, t.line);
    }
  }

  // After ROOT/JOINT: name { body }
  void joint(Document& doc, std::size_t line) {
    const Token& name_token = next();
    if (name_token.text == "{") fail(name_token.line, "joint without a name");
    const std::size_t index = doc.joints.size();
    doc.joints.push_back(BvhJoint{std::string(name_token.text), line, doc.channel_count, {}});
    expect("{");
    while (true) {
      const Token& t = next();
      if (t.text == "}") return;
      if (keyword(t, "OFFSET")) {
        offset();
      } else if (keyword(t, "CHANNELS")) {
        const Token& count_token = next();
        const double count = finite_field(count_token.text, FieldLabel{0, {}, "CHANNELS count"}, name_, count_token.line);
        if (count < 0 || count != std::floor(count) || count > 1000)
          fail(count_token.line, "CHANNELS count '" + std::string(count_token.text) + "' is not valid");
        if (!doc.joints[index].channels.empty())
          fail(t.line, "joint '" + doc.joints[index].name + "' has a second CHANNELS line");
        for (int c = 0; c < static_cast<int>(count); ++c) {
          const Token& ch = next();
          const std::string l = lower(ch.text);
          const bool known = l.size() == 9 && (l[0] == 'x' || l[0] == 'y' || l[0] == 'z') &&
                             (l.substr(1) == "position" || l.substr(1) == "rotation");
          if (!known)
            fail(ch.line, "unknown channel '" + std::string(ch.text) +
                              "' (expected Xposition, Yposition, Zposition, Xrotation, Yrotation "
                              "or Zrotation)");
          doc.joints[index].channels.emplace_back(ch.text);
        }
        doc.joints[index].first_channel = doc.channel_count;
        doc.channel_count += static_cast<std::size_t>(count);
      } else if (keyword(t, "JOINT")) {
        joint(doc, t.line);
      } else if (keyword(t, "End")) {
        expect("Site");
        expect("{");
        expect("OFFSET");
        offset();
        expect("}");
      } else {
        fail(t.line, "unexpected '" + std::string(t.text) + "' in joint '" +
                         doc.joints[index].name + "'");
      }
    }
  }

  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  const std::string& name_;
  std::size_t end_line_;
};

void select_joint(Document& doc, const std::string& name, const ReadOptions& options,
                  std::vector<std::string>& warnings) {
  std::string list;
  for (const BvhJoint& j : doc.joints) {
    doc.joint_names.push_back(j.name);
    list += (list.empty() ? "" : ", ") + j.name;
  }
  if (options.bvh_joint.empty())
    throw PoseFileError(name, 0, "BVH needs a joint to read (ReadOptions::bvh_joint); joints: " + list);
  std::optional<std::size_t> found;
  for (std::size_t i = 0; i < doc.joints.size(); ++i) {
    if (doc.joints[i].name != options.bvh_joint) continue;
    if (found) {
      warnings.push_back(name + ":" + std::to_string(doc.joints[i].line) + ": a second joint named '" +
                         options.bvh_joint + "'; using the first (line " +
                         std::to_string(doc.joints[*found].line) + ")");
      break;
    }
    found = i;
  }
  if (!found)
    throw PoseFileError(name, 0, "no joint '" + options.bvh_joint + "' in the hierarchy; joints: " + list);

  const BvhJoint& joint = doc.joints[*found];
  BvhSelection sel;
  sel.joint = *found;
  std::size_t rotations = 0;
  std::array<std::optional<std::size_t>, 3> pos;
  bool pos_duplicate = false;
  bool rot_duplicate = false;
  std::array<bool, 3> rot_seen{};
  for (std::size_t c = 0; c < joint.channels.size(); ++c) {
    const std::string l = lower(joint.channels[c]);
    const Axis axis = *axis_from_char(l[0]);
    const auto a = static_cast<std::size_t>(axis);
    if (l.substr(1) == "rotation") {
      if (rot_seen[a]) rot_duplicate = true;
      rot_seen[a] = true;
      if (rotations < 3) {
        sel.axes[rotations] = axis;
        sel.rot_channel[rotations] = c;
      }
      ++rotations;
    } else {
      if (pos[a]) pos_duplicate = true;
      pos[a] = c;
    }
  }
  if (rotations != 3 || rot_duplicate)
    throw PoseFileError(name, joint.line,
                        "joint '" + joint.name + "' has " + std::to_string(rotations) +
                            " rotation channel(s); it needs three, one per axis");
  if (pos[0] && pos[1] && pos[2] && !pos_duplicate) {
    sel.pos_channel = std::array<std::size_t, 3>{*pos[0], *pos[1], *pos[2]};
  } else if (pos[0] || pos[1] || pos[2]) {
    warnings.push_back(name + ":" + std::to_string(joint.line) + ": joint '" + joint.name +
                       "' has an incomplete set of position channels; reading its rotation only");
  }
  doc.selection = sel;
}

}  // namespace

PoseFile parse_bvh(std::string text, const std::string& name, const ReadOptions& options) {
  auto doc = std::make_shared<Document>();
  doc->format = PoseFormat::Bvh;
  std::vector<std::string> warnings;
  const std::vector<Line> lines = split_lines(text);
  if (is_blank(text)) throw PoseFileError(name, 0, "empty file");

  // HIERARCHY: everything before the line that starts with MOTION.
  std::vector<Token> tokens;
  auto line = lines.begin();
  for (; line != lines.end(); ++line) {
    const std::vector<Span> f = split_whitespace(text, line->text);
    if (!f.empty() && lower(view(text, f[0])) == "motion") break;
    for (const Span& s : f) tokens.push_back(Token{view(text, s), line->number});
  }
  const std::size_t motion_line = line == lines.end() ? lines.back().number : line->number;
  HierarchyParser(std::move(tokens), name, motion_line).parse(*doc);
  if (line == lines.end()) throw PoseFileError(name, motion_line, "no MOTION section");
  select_joint(*doc, name, options, warnings);

  // MOTION header: "Frames: N" and "Frame Time: dt", each on its own line.
  const auto next_content = [&]() {
    for (++line; line != lines.end() && is_blank(view(text, line->text)); ++line) {
    }
    if (line == lines.end())
      throw PoseFileError(name, lines.back().number, "MOTION section ends before its Frames:/Frame Time: lines");
    return split_whitespace(text, line->text);
  };
  std::vector<Span> f = next_content();
  if (f.size() != 2 || lower(view(text, f[0])) != "frames:")
    throw PoseFileError(name, line->number, "expected 'Frames: <count>'");
  const double frames = finite_field(view(text, f[1]), FieldLabel{0, {}, "frame count"}, name, line->number);
  if (frames < 0 || frames != std::floor(frames))
    throw PoseFileError(name, line->number,
                        "frame count '" + std::string(view(text, f[1])) + "' is not a whole number");
  doc->frames_value = f[1];
  doc->frames_header = static_cast<std::size_t>(frames);
  const std::size_t frames_line = line->number;
  f = next_content();
  if (f.size() != 3 || lower(view(text, f[0])) != "frame" || lower(view(text, f[1])) != "time:")
    throw PoseFileError(name, line->number, "expected 'Frame Time: <seconds>'");
  const double dt = finite_field(view(text, f[2]), FieldLabel{0, {}, "frame time"}, name, line->number);
  if (!(dt > 0.0))
    throw PoseFileError(name, line->number,
                        "frame time '" + std::string(view(text, f[2])) + "' is not positive");

  // Frame rows.
  const BvhSelection& sel = doc->selection;
  const std::size_t base = doc->joints[sel.joint].first_channel;
  PoseSequence poses;
  std::vector<double> values;
  for (++line; line != lines.end(); ++line) {
    if (is_blank(view(text, line->text))) continue;
    const std::vector<Span> v = split_whitespace(text, line->text);
    if (v.size() != doc->channel_count)
      throw PoseFileError(name, line->number,
                          "expected " + std::to_string(doc->channel_count) +
                              " values per frame (the HIERARCHY's channels), found " +
                              std::to_string(v.size()));
    values.resize(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      values[i] = finite_field(view(text, v[i]), FieldLabel{i + 1, {}, {}}, name, line->number);
    std::array<double, 3> angles{};
    std::array<Span, 3> rot{};
    for (std::size_t a = 0; a < 3; ++a) {
      rot[a] = v[base + sel.rot_channel[a]];
      angles[a] = values[base + sel.rot_channel[a]];
    }
    const std::size_t k = poses.orientation.size();
    poses.time.push_back(static_cast<double>(k) * dt);
    poses.orientation.push_back(euler_to_quat(sel.axes, angles));
    doc->bvh_rot.push_back(rot);
    doc->bvh_angles.push_back(angles);
    if (sel.pos_channel) {
      std::array<Span, 3> pos{};
      Vec3 p;
      for (std::size_t a = 0; a < 3; ++a) {
        pos[a] = v[base + (*sel.pos_channel)[a]];
        p[static_cast<Eigen::Index>(a)] = values[base + (*sel.pos_channel)[a]];
      }
      doc->bvh_pos.push_back(pos);
      poses.position.push_back(p);
    }
  }
  if (poses.size() == 0) throw PoseFileError(name, 0, "no samples (no frame rows after MOTION)");
  if (poses.size() != doc->frames_header)
    warnings.push_back(name + ":" + std::to_string(frames_line) + ": Frames: says " +
                       std::to_string(doc->frames_header) + " but " + std::to_string(poses.size()) +
                       " frame rows follow; using all " + std::to_string(poses.size()));
  doc->text = std::move(text);
  return PoseFile(name, std::move(poses), std::move(doc), std::move(warnings));
}

std::string render_bvh(const PoseFile& original, const PoseSequence& poses) {
  const Document& doc = original.document();
  const PoseSequence& old = original.poses();
  std::vector<Edit> edits;
  if (poses.size() != doc.frames_header)
    edits.push_back({doc.frames_value, std::to_string(poses.size())});
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (!same_value(poses.orientation[k], old.orientation[k])) {
      const std::array<double, 3> deg =
          quat_to_euler_nearest(poses.orientation[k], doc.selection.axes, doc.bvh_angles[k]);
      for (std::size_t a = 0; a < 3; ++a) edits.push_back({doc.bvh_rot[k][a], format_number(deg[a])});
    }
    if (poses.has_position())
      for (int a = 0; a < 3; ++a)
        if (!same_value(poses.position[k][a], old.position[k][a]))
          edits.push_back({doc.bvh_pos[k][static_cast<std::size_t>(a)], format_number(poses.position[k][a])});
  }
  return apply_edits(doc.text, std::move(edits));
}

}  // namespace posefair::formats::detail
