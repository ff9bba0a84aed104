#pragma once
// The raw-sample log ("pflog"): what the recorder writes and the replay driver reads. A binary,
// little-endian, append-only file that survives a crash at any byte: every record carries its
// length and a CRC-32, so a reader returns everything up to the first record that is not whole
// and intact, and says where that record starts. The byte layout is in docs/recording.md.
//
//   file    = header record*
//   header  = "PFLOG\0\0\1"  version:u16  header_length:u16
//             stream_count:u16 { id:u32 name:str16 source:str16 }*  [reserved bytes]  crc:u32
//   record  = body_length:u32  type:u8  body[body_length]  crc:u32   (crc over type + body)
//   sample  = stream_id:u32 sequence:u64 time:f64 device_time:f64 receive_time:f64 flags:u32
//             w:f64 x:f64 y:f64 z:f64 px:f64 py:f64 pz:f64                 (96 bytes, type 1)
//   imu sample = sample  gx:f64 gy:f64 gz:f64 ax:f64 ay:f64 az:f64 mx:f64 my:f64 mz:f64
//                                                                            (168 bytes, type 2)
// A sample with raw inertial readings (or without an orientation) is written as type 2, every
// other as type 1, so a log without raw readings is byte for byte what it was before type 2,
// and an older reader skips (and counts) type 2 records instead of misreading them.
//
// Rotation: a writer with max_file_bytes set continues a recording in further files, each a
// complete log with the same header: "<base>.pflog" (the path as given), then
// "<base>.1.pflog", "<base>.2.pflog", ... where <base> is the path without a trailing
// ".pflog" (a path not ending in ".pflog" gets ".1.pflog" appended whole).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/sample.hpp"

namespace posefair::formats {

// ---------------------------------------------------------------------------------------------
// Format constants

inline constexpr unsigned char kSampleLogMagic[8] = {'P', 'F', 'L', 'O', 'G', 0, 0, 1};
inline constexpr std::uint16_t kSampleLogVersion = 1;
// magic + version + header_length: the part every version keeps.
inline constexpr std::size_t kSampleLogPreambleBytes = 12;
// The smallest valid header: preamble, stream_count = 0, crc.
inline constexpr std::size_t kSampleLogMinHeaderBytes = kSampleLogPreambleBytes + 2 + 4;
inline constexpr std::size_t kSampleLogMaxHeaderBytes = 0xFFFF;
// body_length:u32 + type:u8 before the body, crc:u32 after it.
inline constexpr std::size_t kRecordOverheadBytes = 4 + 1 + 4;
inline constexpr std::size_t kSampleBodyBytes = 4 + 8 + 3 * 8 + 4 + 4 * 8 + 3 * 8;  // 96
inline constexpr std::size_t kSampleRecordBytes = kRecordOverheadBytes + kSampleBodyBytes;  // 105
inline constexpr std::size_t kImuSampleBodyBytes = kSampleBodyBytes + 9 * 8;                     // 168
inline constexpr std::size_t kImuSampleRecordBytes = kRecordOverheadBytes + kImuSampleBodyBytes;  // 177
// A body_length above this is treated as a corrupt length field, not as a huge record.
inline constexpr std::uint32_t kMaxRecordBodyBytes = 1u << 20;

// Record kinds. Readers skip (and count) kinds they do not know, so new kinds (markers,
// configuration snapshots, driver diagnostics ...) can be added without a version bump.
enum class RecordType : std::uint8_t {
  Sample = 1,
  ImuSample = 2,  // a sample with raw inertial readings or without an orientation (issue 17)
};

// ---------------------------------------------------------------------------------------------
// Header

struct StreamInfo {
  std::uint32_t id = 0;
  std::string name;    // e.g. "head"; UTF-8, at most 65535 bytes
  std::string source;  // the driver / device description, e.g. "serial:/dev/ttyUSB0 bno085"

  friend bool operator==(const StreamInfo&, const StreamInfo&) = default;
};

struct SampleLogHeader {
  std::uint16_t version = kSampleLogVersion;
  std::vector<StreamInfo> streams;

  const StreamInfo* find(std::uint32_t stream_id) const;
  friend bool operator==(const SampleLogHeader&, const SampleLogHeader&) = default;
};

// The header's bytes, CRC included. Throws std::invalid_argument for duplicate stream ids, a
// name or source longer than 65535 bytes, more than 65535 streams, or a header that would be
// longer than 65535 bytes.
std::vector<unsigned char> encode_sample_log_header(const SampleLogHeader& header);

// The record a sample is written as: ImuSample when it has kHasGyro, kHasAccel, kHasMag or
// kNoOrientation, else Sample; and that record's size in bytes.
RecordType sample_record_type(const Sample& sample);
std::size_t sample_record_bytes(const Sample& sample);
// A whole sample record (length, type, body, CRC) into out[0, sample_record_bytes(sample));
// returns that size. Values are stored bit for bit (NaN payloads, -0, non-unit quaternions
// included); the position (and in an ImuSample the three readings) is written even when its
// flag is not set (whatever the sample holds, normally zero).
std::size_t encode_sample_record(const Sample& sample, unsigned char* out);
// The sample from a sample body (kSampleBodyBytes bytes at `body`), and from an IMU sample
// body (kImuSampleBodyBytes).
Sample decode_sample_body(const unsigned char* body);
Sample decode_imu_sample_body(const unsigned char* body);

// ---------------------------------------------------------------------------------------------
// Errors

// A log that cannot be opened, a bad header, or a writer that cannot start. what() reads
// "<path>: <message>" or, when tied to a place in the file, "<path>: offset N: <message>".
class SampleLogError : public std::runtime_error {
 public:
  SampleLogError(std::string path, std::optional<std::uint64_t> offset, std::string message);
  const std::string& path() const noexcept { return path_; }
  const std::optional<std::uint64_t>& offset() const noexcept { return offset_; }
  const std::string& message() const noexcept { return message_; }

 private:
  std::string path_;
  std::optional<std::uint64_t> offset_;
  std::string message_;
};

// ---------------------------------------------------------------------------------------------
// Writer

struct SampleLogWriterOptions {
  // Preallocated at construction; append() never allocates. At least 4096.
  std::size_t buffer_bytes = 256 * 1024;
  // append() flushes once the buffer holds more than this (<= buffer_bytes).
  std::size_t flush_bytes = 64 * 1024;
  // maybe_flush(now) flushes when more than this many seconds passed since the last flush.
  double flush_interval = 1.0;
  // Rotation: start the next file before a file would grow beyond this many bytes (header
  // included). A file always takes at least one record, so a limit below header + one record
  // gives one record per file. 0: never rotate.
  std::uint64_t max_file_bytes = 0;
  // false: refuse to start when the path (or "<base>.1.pflog") exists. true: replace it and
  // remove the "<base>.N.pflog" files of an earlier recording (N = 1, 2, ... while they exist).
  bool overwrite = false;
  // fdatasync after every flush (and before a rotated file is closed). Off only for tests and
  // benchmarks: without it a crash can lose data the writer reported as flushed.
  bool sync = true;
};

struct SampleLogWriterStats {
  std::uint64_t samples_appended = 0;  // accepted by append()
  std::uint64_t samples_written = 0;   // handed to the file system by a flush that succeeded
  std::uint64_t samples_dropped = 0;   // refused by append() (buffer full after a failed
                                       // write), or still unwritten at close()
  std::uint64_t bytes_written = 0;     // over all files, headers included
  std::uint64_t flushes = 0;           // flushes that wrote something and succeeded
  std::uint64_t write_errors = 0;      // failed write/fdatasync/open of a rotated file
  std::uint64_t files = 0;             // files started (1 + rotations)
  int last_errno = 0;                  // errno of the latest failure, 0 if none
};

// Appends samples to a log, buffered in memory, written with write(2) + fdatasync(2).
//
// Threading: one thread at a time (the recorder's); none of it is real-time safe (flushes
// block on the disk), so a real-time thread hands samples over through a queue.
//
// Failures never lose data silently: a failed write keeps the data in the buffer (the next
// flush rewrites it at the same file offset), is counted in write_errors and reported by the
// return value of flush()/maybe_flush(); until a flush succeeds again append() no longer
// flushes by itself (no system call per sample against a full disk) and, once the buffer is
// full, refuses samples (append() returns false, samples_dropped counts them).
class SampleLogWriter {
 public:
  // Creates the file and writes the header (synced). Throws SampleLogError when the file
  // cannot be created or written, std::invalid_argument for a bad header or bad options.
  SampleLogWriter(const std::filesystem::path& path, SampleLogHeader header,
                  SampleLogWriterOptions options = {});
  SampleLogWriter(const SampleLogWriter&) = delete;
  SampleLogWriter& operator=(const SampleLogWriter&) = delete;
  // close(), errors ignored (call close() first to see them).
  ~SampleLogWriter();

  // Adds the sample to the buffer; may flush (and rotate). Never allocates. Returns false
  // only when the sample was dropped (counted). I/O errors of the flushes it triggers are
  // counted in stats().write_errors and reported by the next flush().
  bool append(const Sample& sample);

  // Writes everything buffered (rotating as needed) and syncs it. True when the buffer is
  // empty afterwards and everything reached the disk; false (counted) otherwise.
  bool flush();

  // The periodic policy, for the recorder's loop: flushes when the buffer holds more than
  // flush_bytes or when more than flush_interval seconds (of `now`, any steady clock in
  // seconds) passed since the last flush. While nothing is buffered the interval restarts,
  // so data waits at most flush_interval plus the calling period. Returns flush()'s result,
  // or true when no flush was due.
  bool maybe_flush(double now);

  // Flushes, syncs and closes the current file. Whatever could not be written is counted in
  // samples_dropped. Returns true when everything appended reached the file. Afterwards
  // append() drops everything (counted) and flush() returns false.
  bool close();

  const SampleLogWriterStats& stats() const { return stats_; }
  // The latest flush failed (e.g. ENOSPC; stats().last_errno says why) and none succeeded since.
  bool failing() const { return failing_; }
  std::size_t buffered_bytes() const { return used_; }
  // The file being written now (its name changes with rotation).
  std::string_view current_path() const { return current_path_; }
  // 0 for the path given, N for "<base>.N.pflog".
  std::uint64_t current_index() const { return index_; }
  const SampleLogHeader& header() const { return header_; }

 private:
  int open_file(std::uint64_t index, int* fd_out);  // 0 or errno
  bool open_next_file();  // rotation: opens file index_ + 1, then syncs and closes the current
  bool write_chunk(std::size_t begin, std::size_t end);
  bool sync_current();
  void fail(int error);
  void format_path(std::uint64_t index);

  SampleLogHeader header_;
  SampleLogWriterOptions options_;
  std::vector<unsigned char> header_bytes_;
  std::string base_;          // the path without ".pflog"
  std::string first_path_;    // the path as given
  std::string current_path_;  // capacity reserved at construction: formatting never allocates
  std::string directory_;     // for fsync after creating a file
  int fd_ = -1;
  std::uint64_t index_ = 0;
  std::uint64_t file_bytes_ = 0;  // committed bytes in the current file (header + whole records)
  std::unique_ptr<unsigned char[]> buffer_;
  std::size_t used_ = 0;  // buffer_[0, used_): whole records not yet written
  std::uint64_t buffered_samples_ = 0;
  bool dirty_ = false;        // written to the current file since its last fdatasync
  bool must_rotate_ = false;  // the current file is full: the next write starts a new one
  bool failing_ = false;      // the latest flush failed: append() does not flush by itself
  bool closed_ = false;
  bool have_now_ = false;
  double last_now_ = 0.0;         // the latest `now` given to maybe_flush
  double last_flush_time_ = 0.0;  // the `now` of the latest flush (or of an empty buffer)
  SampleLogWriterStats stats_;
};

// The path of part `index` of a rotated recording whose first file is `first` (index 0 is
// `first` itself): "run.pflog" -> "run.1.pflog", "run.2.pflog"; "run.log" -> "run.log.1.pflog".
std::filesystem::path sample_log_part_path(const std::filesystem::path& first, std::uint64_t index);

// The existing files of a recording in order: `first`, then "<base>.1.pflog", ... up to the
// first index that does not exist. Throws SampleLogError when `first` does not exist.
std::vector<std::filesystem::path> sample_log_files(const std::filesystem::path& first);

// ---------------------------------------------------------------------------------------------
// Reader

// The first record that could not be read. Nothing after it is read: its length field cannot
// be trusted, so neither can the position of anything behind it.
struct SampleLogProblem {
  std::string path;
  std::uint64_t offset = 0;        // where the bad record starts
  std::uint64_t unread_bytes = 0;  // file size - offset
  // "<path>: offset N: truncated record (expected 105 bytes, 12 present)",
  // "<path>: offset N: record CRC mismatch (stored 0x..., computed 0x...)", ...
  std::string message;
};

struct SampleLogStats {
  std::uint64_t records = 0;                 // intact records read, any type
  std::uint64_t samples = 0;                 // sample records returned
  std::uint64_t unknown_records = 0;         // intact records of a type this reader skips
  std::uint64_t unknown_stream_samples = 0;  // samples whose stream id is not in the header
  std::uint64_t bytes = 0;                   // header + intact records
  std::vector<SampleLogProblem> problems;    // at most one per file; empty: read to the end
};

// Streams a log record by record. The constructor reads and checks the header.
class SampleLogReader {
 public:
  // Throws SampleLogError: cannot open, "not a posefair sample log (bad magic)",
  // "unsupported format version V (this reader reads 1)", "truncated header ...",
  // "header CRC mismatch ...", "malformed stream table ...".
  explicit SampleLogReader(const std::filesystem::path& path);
  SampleLogReader(const SampleLogReader&) = delete;
  SampleLogReader& operator=(const SampleLogReader&) = delete;
  ~SampleLogReader();

  const SampleLogHeader& header() const { return header_; }
  std::uint64_t file_size() const { return file_size_; }

  // The next sample (records of unknown types are skipped and counted). False at the end of
  // the file or at the first bad record (then stats().problems holds it). Never throws for
  // damage after the header.
  bool next(Sample& out);

  const SampleLogStats& stats() const { return stats_; }

 private:
  void read_header();
  void problem(std::uint64_t offset, std::string message);
  std::size_t read_some(unsigned char* out, std::size_t n);

  std::string path_;
  std::FILE* file_ = nullptr;
  SampleLogHeader header_;
  std::uint64_t file_size_ = 0;
  std::uint64_t offset_ = 0;
  bool done_ = false;
  std::vector<unsigned char> body_;
  SampleLogStats stats_;
};

struct SampleLogContents {
  SampleLogHeader header;
  std::vector<Sample> samples;
  SampleLogStats stats;
};

// A sample log by its name (".pflog") or its first bytes (the magic); the test the replay
// driver and posefair fuse use to tell a log from a pose or IMU file. Reads at most 8 bytes;
// false for a file that cannot be opened (and is not named .pflog).
bool is_sample_log_file(const std::filesystem::path& path);

// The whole file: header errors throw SampleLogError; damage after the header does not throw
// (stats.problems says where the intact part ends).
SampleLogContents read_sample_log(const std::filesystem::path& path);

// A rotated recording (sample_log_files(first)), concatenated in order; stats summed, problems
// of every file listed (a damaged part does not stop the parts after it: each starts with its
// own header). Throws SampleLogError when a part's header differs from the first's.
SampleLogContents read_sample_log_set(const std::filesystem::path& first);

// ---------------------------------------------------------------------------------------------
// Little-endian helpers (shared by the writer and the reader)
namespace detail {
inline void put_u16(unsigned char* p, std::uint16_t v) {
  p[0] = static_cast<unsigned char>(v);
  p[1] = static_cast<unsigned char>(v >> 8);
}
inline void put_u32(unsigned char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
inline void put_u64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
inline std::uint16_t get_u16(const unsigned char* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t get_u32(const unsigned char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
inline std::uint64_t get_u64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
// zlib's crc32 (the CRC-32 of gzip and PNG) of `n` bytes.
std::uint32_t crc32(const unsigned char* data, std::size_t n);
}  // namespace detail

}  // namespace posefair::formats
