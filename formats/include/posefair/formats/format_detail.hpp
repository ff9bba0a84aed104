#pragma once
// Internal to posefair_formats: the layout a parsed pose file keeps so it can be written back,
// and the helpers the format readers and writers share. Not a stable interface.
#include <array>
#include <bit>
#include <cstdint>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/euler_angles.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats::detail {

// A range of the original text.
struct Span {
  std::size_t begin = 0;
  std::size_t size = 0;
  std::size_t end() const { return begin + size; }
};

// Where one TUM/CSV sample's pose fields are in the original text.
struct PoseSpans {
  Span time;
  std::array<Span, 4> quat;  // w, x, y, z
  std::array<Span, 3> pos;   // valid when the file has positions
};

struct CsvColumns {
  std::size_t time = 0;
  std::array<std::size_t, 4> quat{};  // column index of w, x, y, z
  std::optional<std::array<std::size_t, 3>> pos;
};

struct BvhJoint {
  std::string name;
  std::size_t line = 0;                   // the ROOT/JOINT line
  std::size_t first_channel = 0;          // index of its first value in a motion row
  std::vector<std::string> channels;      // as written, e.g. "Zrotation"
};

struct BvhSelection {
  std::size_t joint = 0;                     // index into joints
  std::array<Axis, 3> axes{};                // rotation channel order
  std::array<std::size_t, 3> rot_channel{};  // channel index (within the joint) of each angle
  std::optional<std::array<std::size_t, 3>> pos_channel;  // X, Y, Z position channels
};

struct Document {
  PoseFormat format = PoseFormat::Tum;
  // The original file, byte for byte. For a fresh document: only its header text.
  std::string text;
  bool fresh = false;

  // TUM and CSV: one entry per kept sample.
  std::vector<PoseSpans> rows;
  bool has_position = false;
  // CSV: whole lines (with their newline) of rows dropped by skip_missing.
  std::vector<Span> removed;
  CsvColumns csv;
  bool csv_w_first = true;  // fresh CSV only

  // BVH.
  std::vector<BvhJoint> joints;
  std::vector<std::string> joint_names;
  BvhSelection selection;
  std::size_t channel_count = 0;
  Span frames_value;  // the number after "Frames:"
  std::size_t frames_header = 0;
  std::vector<std::array<Span, 3>> bvh_rot;     // per frame, the selected joint's angle fields
  std::vector<std::array<double, 3>> bvh_angles;  // per frame, their values (degrees)
  std::vector<std::array<Span, 3>> bvh_pos;     // per frame, its position fields (if any)
};

// ---- text helpers (text_fields.cpp) ----

std::string_view trim(std::string_view s);
bool is_blank(std::string_view s);

struct Line {
  std::size_t number = 0;  // 1-based
  Span text;               // without the line break (and without a trailing '\r')
  Span full;               // including the line break, if any
};
std::vector<Line> split_lines(std::string_view text);

// Whitespace-separated fields of text[line], as absolute spans.
std::vector<Span> split_whitespace(std::string_view text, Span line);

// Comma-separated fields of text[line] (double quotes protect commas), as absolute spans,
// surrounding blanks excluded.
std::vector<Span> split_commas(std::string_view text, Span line);

inline std::string_view view(std::string_view text, Span s) { return text.substr(s.begin, s.size); }

// Strict number parsing: blanks and one pair of double quotes around it are allowed, a leading
// '+' is allowed, the rest must be a complete number. nan/inf parse (as non-finite values).
std::optional<double> parse_number(std::string_view field);

// The shortest text that parses back to exactly `v`.
std::string format_number(double v);

// Bit-identical doubles (so -0.0 and 0.0 differ): a pose field keeps its original text on
// write only when the new value is exactly the one read.
inline bool same_value(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
inline bool same_value(const Quat& a, const Quat& b) {
  return same_value(a.w(), b.w()) && same_value(a.x(), b.x()) && same_value(a.y(), b.y()) &&
         same_value(a.z(), b.z());
}

// Lower-cased copy.
std::string lower(std::string_view s);

// ---- validation shared by the readers (text_fields.cpp) ----

// How an error names a field: "field 3", "field 2 (gt_qw)", or a fixed text ("frame time").
// Built only when there is an error, so reading stays allocation-free per field.
struct FieldLabel {
  std::size_t number = 0;        // 1-based field number
  std::string_view column;       // CSV header name, if any
  std::string_view text;         // used instead of the number when not empty
  std::string str() const;
};

// Throws PoseFileError unless `field` is a finite number.
double finite_field(std::string_view field, const FieldLabel& label, const std::string& name,
                    std::size_t line);

// |q| checked against the tolerance and renormalised; throws for zero, non-finite or
// non-unit quaternions.
Quat unit_quaternion(double w, double x, double y, double z, double tolerance,
                     const std::string& name, std::size_t line);

// Throws when t < previous.
void check_time_order(double previous, double t, const std::string& name, std::size_t line);

// ---- writers' edit list (pose_file.cpp) ----

struct Edit {
  Span span;
  std::string replacement;
};
// text with every edit applied (edits must not overlap; any order).
std::string apply_edits(std::string_view text, std::vector<Edit> edits);

// ---- TUM/CSV pose edits (pose_edits.cpp) ----

// Appends one edit per changed value of each row of doc.rows (TUM and CSV): the time, all four
// quaternion fields (w, x, y, z spans) when the orientation changed, and each changed position
// field when `poses` has positions. `old` is the sequence the document was read as.
void append_pose_edits(const Document& doc, const PoseSequence& old, const PoseSequence& poses,
                       std::vector<Edit>& edits);

// ---- the formats ----

PoseFile parse_tum(std::string text, const std::string& name, const ReadOptions& options);
PoseFile parse_csv(std::string text, const std::string& name, const ReadOptions& options);
PoseFile parse_bvh(std::string text, const std::string& name, const ReadOptions& options);

// `poses` has already been checked against the document (sizes, finiteness).
std::string render_tum(const PoseFile& original, const PoseSequence& poses);
std::string render_csv(const PoseFile& original, const PoseSequence& poses);
std::string render_bvh(const PoseFile& original, const PoseSequence& poses);

}  // namespace posefair::formats::detail
