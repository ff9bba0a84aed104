// CSV pose tables: a header line names the columns; time, quaternion and optional position
// columns are found by name, every other column is carried through untouched.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "posefair/formats/format_detail.hpp"

namespace posefair::formats::detail {

namespace {

constexpr const char* kRequired =
    "required: a time column (t, time, timestamp or t_s) and quaternion columns qw, qx, qy, qz "
    "in any order (optionally prefixed, e.g. gt_qw); optional position px, py, pz or tx, ty, tz "
    "or x, y, z";

std::string unquote(std::string_view s) {
  s = trim(s);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trim(s.substr(1, s.size() - 2));
  return std::string(s);
}

std::string join(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += sep;
    out += items[i];
  }
  return out;
}

// "<prefix>q<c><suffix>" with prefix "" or ending in '_', suffix "" or starting with '_'.
struct QuatSet {
  std::array<std::optional<std::size_t>, 4> column;  // w, x, y, z
  std::size_t found() const {
    return static_cast<std::size_t>(std::count_if(column.begin(), column.end(),
                                                  [](const auto& c) { return c.has_value(); }));
  }
};

int component_index(char c) {
  switch (c) {
    case 'w': return 0;
    case 'x': return 1;
    case 'y': return 2;
    case 'z': return 3;
    default: return -1;
  }
}

CsvColumns find_columns(const std::vector<std::string>& names, const std::vector<std::string>& shown,
                        const ReadOptions& options, const std::string& file, std::size_t line) {
  const auto fail = [&](const std::string& what) {
    throw PoseFileError(file, line, what + "; " + kRequired + "; header: " + join(shown));
  };
  CsvColumns cols;

  // Time.
  std::vector<std::size_t> time_cols;
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == "t" || names[i] == "time" || names[i] == "timestamp" || names[i] == "t_s")
      time_cols.push_back(i);

  // Quaternion sets keyed by (prefix, suffix).
  std::map<std::pair<std::string, std::string>, QuatSet> sets;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    for (std::size_t p = n.find('q'); p != std::string::npos; p = n.find('q', p + 1)) {
      if (p > 0 && n[p - 1] != '_') continue;
      if (p + 1 >= n.size() || component_index(n[p + 1]) < 0) continue;
      if (p + 2 < n.size() && n[p + 2] != '_') continue;
      QuatSet& set = sets[{n.substr(0, p), n.substr(p + 2)}];
      auto& slot = set.column[static_cast<std::size_t>(component_index(n[p + 1]))];
      if (slot) fail("duplicate quaternion column '" + shown[i] + "'");
      slot = i;
    }
  }
  std::vector<std::pair<std::string, std::string>> complete;
  const std::pair<std::string, std::string>* best = nullptr;
  std::size_t best_found = 0;
  for (const auto& [key, set] : sets) {
    if (options.csv_prefix && key.first != lower(*options.csv_prefix)) continue;
    if (set.found() == 4) complete.push_back(key);
    if (set.found() > best_found) {
      best_found = set.found();
      best = &key;
    }
  }

  std::vector<std::string> missing;
  if (time_cols.empty()) missing.push_back("time column");
  if (complete.empty()) {
    if (best == nullptr) {
      std::string what = "quaternion columns qw, qx, qy, qz";
      if (options.csv_prefix) what += " with prefix '" + *options.csv_prefix + "'";
      missing.push_back(what);
    } else {
      std::vector<std::string> absent;
      const QuatSet& set = sets.at(*best);
      for (std::size_t c = 0; c < 4; ++c)
        if (!set.column[c]) absent.push_back(best->first + "q" + "wxyz"[c] + best->second);
      missing.push_back("quaternion column" + std::string(absent.size() > 1 ? "s " : " ") +
                        join(absent));
    }
  }
  if (!missing.empty()) fail("missing " + join(missing, " and "));
  if (time_cols.size() > 1)
    fail("several time columns (" + shown[time_cols[0]] + ", " + shown[time_cols[1]] + ")");
  if (complete.size() > 1) {
    std::vector<std::string> prefixes;
    for (const auto& key : complete) prefixes.push_back("'" + key.first + "q*" + key.second + "'");
    fail("several quaternion column sets (" + join(prefixes) +
         "); choose one with ReadOptions::csv_prefix");
  }
  cols.time = time_cols[0];
  const QuatSet& q = sets.at(complete[0]);
  for (std::size_t c = 0; c < 4; ++c) cols.quat[c] = *q.column[c];

  // Position: "<quaternion prefix>{p,t,}{x,y,z}[_suffix]", one complete family.
  const std::string& prefix = complete[0].first;
  std::map<std::pair<std::string, std::string>, std::array<std::optional<std::size_t>, 3>> pos;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    if (n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = n.substr(prefix.size());
    for (const std::string family : {"p", "t", ""}) {
      if (rest.size() < family.size() + 1 || rest.compare(0, family.size(), family) != 0) continue;
      const char axis = rest[family.size()];
      if (axis != 'x' && axis != 'y' && axis != 'z') continue;
      const std::string suffix = rest.substr(family.size() + 1);
      if (!suffix.empty() && suffix.front() != '_') continue;
      auto& slot = pos[{family, suffix}][static_cast<std::size_t>(axis - 'x')];
      if (slot) fail("duplicate position column '" + shown[i] + "'");
      slot = i;
    }
  }
  std::vector<std::array<std::size_t, 3>> pos_sets;
  std::vector<std::string> pos_names;
  for (const auto& [key, slots] : pos) {
    if (!slots[0] || !slots[1] || !slots[2]) continue;
    pos_sets.push_back({*slots[0], *slots[1], *slots[2]});
    pos_names.push_back(shown[*slots[0]] + "/" + shown[*slots[1]] + "/" + shown[*slots[2]]);
  }
  if (pos_sets.size() > 1) fail("several position column sets (" + join(pos_names) + ")");
  if (pos_sets.size() == 1) cols.pos = pos_sets[0];
  return cols;
}

bool missing_value(std::string_view field) {
  const std::string s = unquote(field);
  if (s.empty()) return true;
  const std::optional<double> v = parse_number(s);
  return v && std::isnan(*v);
}

}  // namespace

PoseFile parse_csv(std::string text, const std::string& name, const ReadOptions& options) {
  auto doc = std::make_shared<Document>();
  doc->format = PoseFormat::Csv;
  const std::vector<Line> lines = split_lines(text);
  auto line = lines.begin();
  while (line != lines.end() && is_blank(view(text, line->text))) ++line;
  if (line == lines.end()) throw PoseFileError(name, 0, "empty file");

  const std::vector<Span> header = split_commas(text, line->text);
  std::vector<std::string> names, shown;
  for (const Span& s : header) {
    shown.push_back(unquote(view(text, s)));
    names.push_back(lower(shown.back()));
  }
  const CsvColumns cols = find_columns(names, shown, options, name, line->number);
  doc->csv = cols;
  doc->has_position = cols.pos.has_value();
  const auto label = [&](std::size_t c) { return FieldLabel{c + 1, shown[c], {}}; };

  PoseSequence poses;
  std::size_t skipped = 0;
  double previous = -std::numeric_limits<double>::infinity();
  for (++line; line != lines.end(); ++line) {
    if (is_blank(view(text, line->text))) continue;
    const std::vector<Span> f = split_commas(text, line->text);
    if (f.size() != header.size())
      throw PoseFileError(name, line->number,
                          "expected " + std::to_string(header.size()) +
                              " fields as in the header, found " + std::to_string(f.size()));
    bool quat_missing = false;
    for (std::size_t c : cols.quat) {
      if (!missing_value(view(text, f[c]))) continue;
      if (!options.skip_missing)
        throw PoseFileError(name, line->number,
                            label(c).str() + " '" + unquote(view(text, f[c])) +
                                "': quaternion is missing (ReadOptions::skip_missing drops such rows)");
      quat_missing = true;
    }
    if (quat_missing) {
      doc->removed.push_back(line->full);
      ++skipped;
      continue;
    }
    const double t = finite_field(view(text, f[cols.time]), label(cols.time), name, line->number);
    double q[4];
    for (std::size_t c = 0; c < 4; ++c)
      q[c] = finite_field(view(text, f[cols.quat[c]]), label(cols.quat[c]), name, line->number);
    PoseSpans spans{f[cols.time], {f[cols.quat[0]], f[cols.quat[1]], f[cols.quat[2]], f[cols.quat[3]]}, {}};
    if (cols.pos) {
      Vec3 p;
      for (std::size_t c = 0; c < 3; ++c) {
        const std::size_t col = (*cols.pos)[c];
        p[static_cast<Eigen::Index>(c)] = finite_field(view(text, f[col]), label(col), name, line->number);
        spans.pos[c] = f[col];
      }
      poses.position.push_back(p);
    }
    check_time_order(previous, t, name, line->number);
    previous = t;
    poses.time.push_back(t);
    poses.orientation.push_back(
        unit_quaternion(q[0], q[1], q[2], q[3], options.unit_tolerance, name, line->number));
    doc->rows.push_back(spans);
  }
  if (poses.size() == 0)
    throw PoseFileError(name, 0,
                        skipped > 0 ? "no samples (every row's quaternion is missing)" : "no samples");
  doc->text = std::move(text);
  return PoseFile(name, std::move(poses), std::move(doc), {}, skipped);
}

std::string render_csv(const PoseFile& original, const PoseSequence& poses) {
  const Document& doc = original.document();
  if (doc.fresh) {
    std::string out = doc.text;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const Quat& q = poses.orientation[k];
      out += format_number(poses.time[k]);
      const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
      const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
      for (double v : doc.csv_w_first ? wxyz : xyzw) {
        out += ',';
        out += format_number(v);
      }
      if (doc.has_position)
        for (int i = 0; i < 3; ++i) {
          out += ',';
          out += format_number(poses.position[k][i]);
        }
      out += '\n';
    }
    return out;
  }
  const PoseSequence& old = original.poses();
  std::vector<Edit> edits;
  for (const Span& s : doc.removed) edits.push_back({s, {}});
  append_pose_edits(doc, old, poses, edits);
  return apply_edits(doc.text, std::move(edits));
}

}  // namespace posefair::formats::detail
