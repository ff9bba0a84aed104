#pragma once
// Pose files: read a TUM, CSV or BVH file into a PoseSequence, and write a sequence back in
// the same file's own format and layout (everything that is not a pose value is kept as it
// was, byte for byte).
//
// Formats
//   TUM  `timestamp tx ty tz qx qy qz qw` (w LAST), whitespace separated; `#` starts a comment
//        line; blank lines are skipped. Positions are always present.
//   CSV  The first non-blank line is a header. Columns are found by name (case-insensitive):
//        time: `t`, `time`, `timestamp` or `t_s`;
//        quaternion: `qw`,`qx`,`qy`,`qz`, optionally with a prefix ending in `_` and/or a
//        suffix starting with `_` (`gt_qw`); their order in the header does not matter;
//        position (optional): `px,py,pz`, `tx,ty,tz` or `x,y,z` with the quaternion's prefix
//        and any common `_unit` suffix (`gt_px_m`). Other columns are carried through
//        unchanged on write. Fields are comma separated; "double-quoted" fields may hold commas.
//   BVH  HIERARCHY + MOTION. One joint (ReadOptions::bvh_joint) becomes the sequence: its
//        rotation channels (degrees; R = R_first · R_second · R_third in CHANNELS order) and,
//        if it has all three position channels (the root usually does), its positions as the
//        raw channel values. Time of frame k is k · Frame Time. The joint needs exactly three
//        rotation channels, one per axis. Note: some files start with a reference pose, e.g.
//        frame 0 of the CMU conversion 01_01.bvh is a T-pose, not motion; the reader does not
//        skip it (callers that want motion only should drop sample 0 themselves).
//
// Values
//   Quaternions with | |q| - 1 | <= unit_tolerance are renormalised on read (unless |q|² is
//   already within 4e-15 of 1, so reading a file this library wrote is exact); beyond it
//   they are an error. Times must not decrease (equal consecutive times are fine).
//   Writing uses the shortest text that reads back as the same double, and a pose field whose
//   value is unchanged (== the value read) keeps its original text, so read -> write -> read
//   reproduces every value bit for bit and unchanged files come back byte-identical.
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/pose_sequence.hpp"

namespace posefair::formats {

enum class PoseFormat { Tum, Csv, Bvh };

// "tum", "csv", "bvh".
std::string_view to_string(PoseFormat format);

// By extension, case-insensitive: .txt/.tum -> Tum, .csv -> Csv, .bvh -> Bvh; else nullopt.
std::optional<PoseFormat> format_from_extension(const std::filesystem::path& path);

// Every problem with a pose file. what() reads "<path>:<line>: <message>"; line is 1-based,
// 0 when the problem is not tied to one line (unknown extension, no samples, I/O errors).
class PoseFileError : public std::runtime_error {
 public:
  PoseFileError(std::string path, std::size_t line, std::string message);
  const std::string& path() const noexcept { return path_; }
  std::size_t line() const noexcept { return line_; }
  const std::string& message() const noexcept { return message_; }

 private:
  std::string path_;
  std::size_t line_;
  std::string message_;
};

struct ReadOptions {
  // nullopt: decided by the file name's extension (see format_from_extension), else an error.
  std::optional<PoseFormat> format;
  // BVH only, required: the joint that becomes the sequence.
  std::string bvh_joint;
  // | |q| - 1 | above this is an error ("non-unit quaternion"); at or below it q is renormalised.
  double unit_tolerance = 1e-2;
  // CSV only: drop rows whose quaternion is missing (any of its four fields `nan` or empty)
  // instead of failing; PoseFile::skipped_rows() counts them and writing leaves them out.
  bool skip_missing = false;
  // CSV only: when the header has several quaternion column sets (gt_qw.. and est_qw..), the
  // prefix of the one to read ("gt_", or "" for plain qw..). nullopt: there must be exactly one.
  std::optional<std::string> csv_prefix;
};

namespace detail {
struct Document;  // the format-specific layout; see format_detail.hpp (internal)
}

// A parsed pose file: the sequence plus everything needed to write the same format back.
// Cheap to copy (the document is shared and immutable).
class PoseFile {
 public:
  PoseFile(std::string name, PoseSequence poses, std::shared_ptr<const detail::Document> document,
           std::vector<std::string> warnings = {}, std::size_t skipped_rows = 0);

  PoseFormat format() const;
  // The name used in error messages (the path as given, or the istream's display name).
  const std::string& name() const { return name_; }
  const PoseSequence& poses() const { return poses_; }
  // Quirks accepted while reading, each as "<name>:<line>: <text>" (e.g. a BVH whose Frames:
  // header disagrees with the rows present).
  const std::vector<std::string>& warnings() const { return warnings_; }
  // CSV rows dropped because of ReadOptions::skip_missing.
  std::size_t skipped_rows() const { return skipped_rows_; }
  // True for files built by make_tum / make_csv (no original text to keep).
  bool is_fresh() const;
  // BVH only: every joint in hierarchy order, and the one that became the sequence.
  const std::vector<std::string>& bvh_joints() const;
  const std::string& bvh_joint() const;

  // Internal: the writers' view of the layout.
  const detail::Document& document() const { return *document_; }

 private:
  std::string name_;
  PoseSequence poses_;
  std::shared_ptr<const detail::Document> document_;
  std::vector<std::string> warnings_;
  std::size_t skipped_rows_ = 0;
};

// Reads a pose file. Throws PoseFileError for anything wrong with it (including a file that
// cannot be opened).
PoseFile read_pose_file(const std::filesystem::path& path, const ReadOptions& options);

// The same from a stream; `name` is used in error messages and, when options.format is
// nullopt, for its extension.
PoseFile parse_pose_file(std::istream& in, const std::string& name, const ReadOptions& options);
PoseFile parse_pose_text(std::string text, const std::string& name, const ReadOptions& options);

// Fresh documents, for writing a new file. make_tum writes "# timestamp tx ty tz qx qy qz qw"
// and one line per sample (positions 0 0 0 when `poses` has none).
struct CsvLayout {
  bool w_first = true;          // qw,qx,qy,qz (true) or qx,qy,qz,qw (false)
  std::string time_column = "t";
  std::string prefix;           // prepended to every quaternion and position column name
};
PoseFile make_tum(const PoseSequence& poses);
// Header `<time_column>,<prefix>qw,...[,<prefix>px,<prefix>py,<prefix>pz]` (positions iff
// `poses` has them).
PoseFile make_csv(const PoseSequence& poses, const CsvLayout& layout = {});

// The text write_pose_file would write. `poses` must have as many samples as
// original.poses() (any number for a fresh document), every field finite, time
// non-decreasing and sized like the orientations, non-zero quaternions; position either empty
// (keep the file's positions) or one per sample. BVH: `poses.time` is not written (the
// Frame Time stays); the Frames: header is set to the number of rows written.
// Quaternions are written as given (pass unit ones: a non-unit one is renormalised when read
// back, so it would not round-trip bit for bit). BVH joints get Euler angles nearest to the
// original row's (see quat_to_euler_nearest).
// Throws std::invalid_argument when `poses` does not fit.
std::string render_pose_file(const PoseFile& original, const PoseSequence& poses);

// Writes render_pose_file(original, poses) to `out` atomically (see write_file_atomically):
// either `out` is completely replaced or it is left as it was. Throws PoseFileError (line 0)
// on I/O errors, std::invalid_argument when `poses` does not fit.
void write_pose_file(const std::filesystem::path& out, const PoseFile& original,
                     const PoseSequence& poses);

}  // namespace posefair::formats
