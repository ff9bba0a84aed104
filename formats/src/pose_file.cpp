// Format dispatch for reading and writing pose files, fresh documents, and the edit list the
// writers use to change only the pose values of the original text.
#include "posefair/formats/pose_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <istream>
#include <iterator>

#include "posefair/formats/atomic_write.hpp"
#include "posefair/formats/format_detail.hpp"

namespace posefair::formats {

namespace {

std::string where(const std::string& path, std::size_t line, const std::string& message) {
  return path + ":" + std::to_string(line) + ": " + message;
}

const std::vector<std::string>& empty_names() {
  static const std::vector<std::string> names;
  return names;
}

PoseFormat resolve_format(const std::string& name, const ReadOptions& options) {
  if (options.format) return *options.format;
  if (auto f = format_from_extension(name)) return *f;
  const std::string ext = std::filesystem::path(name).extension().string();
  throw PoseFileError(name, 0,
                      (ext.empty() ? std::string("no file extension")
                                   : "unknown pose file extension '" + ext + "'") +
                          " (expected .txt, .tum, .csv or .bvh, or give the format explicitly)");
}

void check_poses(const PoseFile& original, const PoseSequence& poses) {
  const detail::Document& doc = original.document();
  const std::size_t n = poses.orientation.size();
  if (!doc.fresh && n != original.poses().size())
    throw std::invalid_argument("pose file '" + original.name() + "' has " +
                                std::to_string(original.poses().size()) + " samples, got " +
                                std::to_string(n));
  if (poses.time.size() != n)
    throw std::invalid_argument("poses have " + std::to_string(n) + " orientations but " +
                                std::to_string(poses.time.size()) + " times");
  if (!poses.position.empty() && poses.position.size() != n)
    throw std::invalid_argument("poses have " + std::to_string(n) + " orientations but " +
                                std::to_string(poses.position.size()) + " positions");
  if (!poses.position.empty() && !original.poses().has_position() && !doc.fresh)
    throw std::invalid_argument("pose file '" + original.name() + "' has no position fields");
  if (doc.fresh && doc.format == PoseFormat::Csv && doc.has_position && n > 0 &&
      poses.position.empty())
    throw std::invalid_argument("this CSV layout has position columns but the poses have none");
  for (std::size_t k = 0; k < n; ++k) {
    const Quat& q = poses.orientation[k];
    if (!q.coeffs().allFinite() || !std::isfinite(poses.time[k]) ||
        (!poses.position.empty() && !poses.position[k].allFinite()))
      throw std::invalid_argument("sample " + std::to_string(k) + " has a non-finite value");
    if (q.squaredNorm() == 0.0)
      throw std::invalid_argument("sample " + std::to_string(k) + " has a zero quaternion");
    if (k > 0 && poses.time[k] < poses.time[k - 1])
      throw std::invalid_argument("sample " + std::to_string(k) + ": time goes backwards");
  }
}

}  // namespace

std::string_view to_string(PoseFormat format) {
  switch (format) {
    case PoseFormat::Tum: return "tum";
    case PoseFormat::Csv: return "csv";
    case PoseFormat::Bvh: return "bvh";
  }
  return "unknown";
}

std::optional<PoseFormat> format_from_extension(const std::filesystem::path& path) {
  const std::string ext = detail::lower(path.extension().string());
  if (ext == ".txt" || ext == ".tum") return PoseFormat::Tum;
  if (ext == ".csv") return PoseFormat::Csv;
  if (ext == ".bvh") return PoseFormat::Bvh;
  return std::nullopt;
}

PoseFileError::PoseFileError(std::string path, std::size_t line, std::string message)
    : std::runtime_error(where(path, line, message)),
      path_(std::move(path)),
      line_(line),
      message_(std::move(message)) {}

PoseFile::PoseFile(std::string name, PoseSequence poses,
                   std::shared_ptr<const detail::Document> document,
                   std::vector<std::string> warnings, std::size_t skipped_rows)
    : name_(std::move(name)),
      poses_(std::move(poses)),
      document_(std::move(document)),
      warnings_(std::move(warnings)),
      skipped_rows_(skipped_rows) {}

PoseFormat PoseFile::format() const { return document_->format; }
bool PoseFile::is_fresh() const { return document_->fresh; }

const std::vector<std::string>& PoseFile::bvh_joints() const {
  return document_->format == PoseFormat::Bvh ? document_->joint_names : empty_names();
}

const std::string& PoseFile::bvh_joint() const {
  static const std::string none;
  if (document_->format != PoseFormat::Bvh) return none;
  return document_->joints[document_->selection.joint].name;
}

PoseFile parse_pose_text(std::string text, const std::string& name, const ReadOptions& options) {
  switch (resolve_format(name, options)) {
    case PoseFormat::Tum: return detail::parse_tum(std::move(text), name, options);
    case PoseFormat::Csv: return detail::parse_csv(std::move(text), name, options);
    case PoseFormat::Bvh: return detail::parse_bvh(std::move(text), name, options);
  }
  throw PoseFileError(name, 0, "unknown pose format");
}

PoseFile parse_pose_file(std::istream& in, const std::string& name, const ReadOptions& options) {
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw PoseFileError(name, 0, "read error");
  return parse_pose_text(std::move(text), name, options);
}

PoseFile read_pose_file(const std::filesystem::path& path, const ReadOptions& options) {
  const std::string name = path.string();
  resolve_format(name, options);  // an unknown extension is reported before opening the file
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw PoseFileError(name, 0, "cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PoseFileError(name, 0, std::string("cannot open: ") + std::strerror(errno));
  return parse_pose_file(in, name, options);
}

PoseFile make_tum(const PoseSequence& poses) {
  auto doc = std::make_shared<detail::Document>();
  doc->format = PoseFormat::Tum;
  doc->fresh = true;
  doc->has_position = true;
  doc->text = "# timestamp tx ty tz qx qy qz qw\n";
  PoseSequence stored = poses;
  if (stored.position.empty()) stored.position.assign(stored.orientation.size(), Vec3::Zero());
  return PoseFile("(new TUM file)", std::move(stored), std::move(doc));
}

PoseFile make_csv(const PoseSequence& poses, const CsvLayout& layout) {
  auto doc = std::make_shared<detail::Document>();
  doc->format = PoseFormat::Csv;
  doc->fresh = true;
  doc->has_position = poses.has_position();
  doc->csv_w_first = layout.w_first;
  const std::string& p = layout.prefix;
  std::string header = layout.time_column;
  header += layout.w_first ? "," + p + "qw," + p + "qx," + p + "qy," + p + "qz"
                           : "," + p + "qx," + p + "qy," + p + "qz," + p + "qw";
  if (doc->has_position) header += "," + p + "px," + p + "py," + p + "pz";
  doc->text = header + "\n";
  return PoseFile("(new CSV file)", poses, std::move(doc));
}

std::string render_pose_file(const PoseFile& original, const PoseSequence& poses) {
  check_poses(original, poses);
  switch (original.format()) {
    case PoseFormat::Tum: return detail::render_tum(original, poses);
    case PoseFormat::Csv: return detail::render_csv(original, poses);
    case PoseFormat::Bvh: return detail::render_bvh(original, poses);
  }
  throw std::invalid_argument("unknown pose format");
}

void write_pose_file(const std::filesystem::path& out, const PoseFile& original,
                     const PoseSequence& poses) {
  const std::string text = render_pose_file(original, poses);
  write_file_atomically(out, text);
}

namespace detail {

std::string apply_edits(std::string_view text, std::vector<Edit> edits) {
  std::sort(edits.begin(), edits.end(),
            [](const Edit& a, const Edit& b) { return a.span.begin < b.span.begin; });
  std::size_t extra = 0;
  for (const Edit& e : edits) extra += e.replacement.size();
  std::string out;
  out.reserve(text.size() + extra);
  std::size_t at = 0;
  for (const Edit& e : edits) {
    out.append(text.substr(at, e.span.begin - at));
    out.append(e.replacement);
    at = e.span.end();
  }
  out.append(text.substr(at));
  return out;
}

}  // namespace detail
}  // namespace posefair::formats
