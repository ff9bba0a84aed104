// The sample log writer: header and record encoding, buffered appends, write(2) + fdatasync,
// size-based rotation. See sample_log.hpp and docs/recording.md.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "posefair/formats/sample_log.hpp"

namespace posefair::formats {

namespace detail {
std::uint32_t crc32(const unsigned char* data, std::size_t n) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  while (n > 0) {  // zlib takes uInt lengths
    const uInt chunk = static_cast<uInt>(std::min<std::size_t>(n, 1u << 30));
    crc = ::crc32(crc, data, chunk);
    data += chunk;
    n -= chunk;
  }
  return static_cast<std::uint32_t>(crc);
}
}  // namespace detail

namespace {

using detail::put_u16;
using detail::put_u32;
using detail::put_u64;

constexpr std::string_view kExtension = ".pflog";

// "run.pflog" -> "run"; anything else stays whole.
std::string part_base(const std::string& first) {
  if (first.size() > kExtension.size() && first.ends_with(kExtension)) {
    return first.substr(0, first.size() - kExtension.size());
  }
  return first;
}

// Writes all of [data, data + n) at `offset`, retrying short writes and EINTR. 0 or errno.
int pwrite_all(int fd, const unsigned char* data, std::size_t n, std::uint64_t offset) {
  while (n > 0) {
    const ssize_t w = ::pwrite(fd, data, n, static_cast<off_t>(offset));
    if (w < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (w == 0) return EIO;
    data += w;
    n -= static_cast<std::size_t>(w);
    offset += static_cast<std::uint64_t>(w);
  }
  return 0;
}

void put_f64(unsigned char* p, double v) { put_u64(p, std::bit_cast<std::uint64_t>(v)); }

std::string errno_text(int error) { return std::error_code(error, std::generic_category()).message(); }

}  // namespace

// ---------------------------------------------------------------------------------------------

SampleLogError::SampleLogError(std::string path, std::optional<std::uint64_t> offset, std::string message)
    : std::runtime_error(path + ": " + (offset ? "offset " + std::to_string(*offset) + ": " : std::string()) +
                         message),
      path_(std::move(path)),
      offset_(offset),
      message_(std::move(message)) {}

std::vector<unsigned char> encode_sample_log_header(const SampleLogHeader& header) {
  if (header.version != kSampleLogVersion) {
    throw std::invalid_argument("sample log: this writer writes format version " +
                                std::to_string(kSampleLogVersion));
  }
  if (header.streams.size() > 0xFFFF) throw std::invalid_argument("sample log: more than 65535 streams");
  std::size_t size = kSampleLogPreambleBytes + 2 + 4;
  std::set<std::uint32_t> ids;
  for (const StreamInfo& s : header.streams) {
    if (!ids.insert(s.id).second) {
      throw std::invalid_argument("sample log: stream id " + std::to_string(s.id) + " appears twice");
    }
    if (s.name.size() > 0xFFFF || s.source.size() > 0xFFFF) {
      throw std::invalid_argument("sample log: stream " + std::to_string(s.id) +
                                  ": name or source longer than 65535 bytes");
    }
    size += 4 + 2 + s.name.size() + 2 + s.source.size();
  }
  if (size > kSampleLogMaxHeaderBytes) {
    throw std::invalid_argument("sample log: header of " + std::to_string(size) +
                                " bytes exceeds the 65535-byte limit (shorter names or sources)");
  }
  std::vector<unsigned char> out(size);
  unsigned char* p = out.data();
  std::memcpy(p, kSampleLogMagic, sizeof kSampleLogMagic);
  put_u16(p + 8, header.version);
  put_u16(p + 10, static_cast<std::uint16_t>(size));
  put_u16(p + 12, static_cast<std::uint16_t>(header.streams.size()));
  p += 14;
  for (const StreamInfo& s : header.streams) {
    put_u32(p, s.id);
    put_u16(p + 4, static_cast<std::uint16_t>(s.name.size()));
    std::memcpy(p + 6, s.name.data(), s.name.size());
    p += 6 + s.name.size();
    put_u16(p, static_cast<std::uint16_t>(s.source.size()));
    std::memcpy(p + 2, s.source.data(), s.source.size());
    p += 2 + s.source.size();
  }
  put_u32(p, detail::crc32(out.data(), size - 4));
  return out;
}

RecordType sample_record_type(const Sample& s) {
  return (s.flags & (kHasGyro | kHasAccel | kHasMag | kNoOrientation)) != 0 ? RecordType::ImuSample
                                                                              : RecordType::Sample;
}

std::size_t sample_record_bytes(const Sample& s) {
  return sample_record_type(s) == RecordType::ImuSample ? kImuSampleRecordBytes : kSampleRecordBytes;
}

std::size_t encode_sample_record(const Sample& s, unsigned char* out) {
  const RecordType type = sample_record_type(s);
  const std::size_t body = type == RecordType::ImuSample ? kImuSampleBodyBytes : kSampleBodyBytes;
  put_u32(out, static_cast<std::uint32_t>(body));
  out[4] = static_cast<unsigned char>(type);
  unsigned char* b = out + 5;
  put_u32(b + 0, s.stream_id);
  put_u64(b + 4, s.sequence);
  put_f64(b + 12, s.time);
  put_f64(b + 20, s.device_time);
  put_f64(b + 28, s.receive_time);
  put_u32(b + 36, s.flags);
  put_f64(b + 40, s.orientation.w());
  put_f64(b + 48, s.orientation.x());
  put_f64(b + 56, s.orientation.y());
  put_f64(b + 64, s.orientation.z());
  put_f64(b + 72, s.position.x());
  put_f64(b + 80, s.position.y());
  put_f64(b + 88, s.position.z());
  if (type == RecordType::ImuSample) {
    unsigned char* p = b + kSampleBodyBytes;
    for (const Vec3* v : {&s.gyro, &s.accel, &s.mag})
      for (int k = 0; k < 3; ++k, p += 8) put_f64(p, (*v)[k]);
  }
  put_u32(b + body, detail::crc32(out + 4, 1 + body));
  return kRecordOverheadBytes + body;
}

std::filesystem::path sample_log_part_path(const std::filesystem::path& first, std::uint64_t index) {
  if (index == 0) return first;
  return std::filesystem::path(part_base(first.string()) + "." + std::to_string(index) + std::string(kExtension));
}

std::vector<std::filesystem::path> sample_log_files(const std::filesystem::path& first) {
  std::error_code ec;
  if (!std::filesystem::exists(first, ec)) {
    throw SampleLogError(first.string(), std::nullopt, ec ? "cannot open: " + ec.message() : "no such file");
  }
  std::vector<std::filesystem::path> files{first};
  for (std::uint64_t i = 1;; ++i) {
    std::filesystem::path p = sample_log_part_path(first, i);
    if (!std::filesystem::exists(p, ec)) break;
    files.push_back(std::move(p));
  }
  return files;
}

// ---------------------------------------------------------------------------------------------
// SampleLogWriter

SampleLogWriter::SampleLogWriter(const std::filesystem::path& path, SampleLogHeader header,
                                 SampleLogWriterOptions options)
    : header_(std::move(header)), options_(options) {
  if (options_.buffer_bytes < 4096) throw std::invalid_argument("sample log writer: buffer_bytes below 4096");
  if (options_.flush_bytes > options_.buffer_bytes) {
    throw std::invalid_argument("sample log writer: flush_bytes larger than buffer_bytes");
  }
  if (!(options_.flush_interval >= 0.0)) {
    throw std::invalid_argument("sample log writer: flush_interval must be >= 0");
  }
  header_bytes_ = encode_sample_log_header(header_);

  first_path_ = path.string();
  if (first_path_.empty()) throw std::invalid_argument("sample log writer: empty path");
  base_ = part_base(first_path_);
  const std::filesystem::path parent = path.parent_path();
  directory_ = parent.empty() ? std::string(".") : parent.string();
  // Room for "<base>.<any u64>.pflog": rotation never allocates.
  current_path_.reserve(std::max(first_path_.size(), base_.size() + 1 + 20 + kExtension.size()) + 1);

  std::error_code ec;
  const std::string second = sample_log_part_path(path, 1).string();
  if (!options_.overwrite) {
    for (const std::string& p : {first_path_, second}) {
      if (std::filesystem::exists(p, ec) || std::filesystem::is_symlink(p, ec)) {
        throw SampleLogError(p, std::nullopt, "exists already (set overwrite to replace the recording)");
      }
    }
  } else {
    // The parts of an earlier, longer recording under the same name would read as ours.
    for (std::uint64_t i = 1;; ++i) {
      const std::filesystem::path p = sample_log_part_path(path, i);
      if (!std::filesystem::exists(p, ec)) break;
      if (!std::filesystem::remove(p, ec) || ec) {
        throw SampleLogError(p.string(), std::nullopt, "cannot remove the earlier recording's part: " + ec.message());
      }
    }
  }

  buffer_ = std::make_unique<unsigned char[]>(options_.buffer_bytes);
  int fd = -1;
  if (const int error = open_file(0, &fd); error != 0) {
    throw SampleLogError(current_path_, std::nullopt, "cannot create the log: " + errno_text(error));
  }
  fd_ = fd;
  index_ = 0;
  file_bytes_ = header_bytes_.size();
  stats_.files = 1;
  stats_.bytes_written = header_bytes_.size();
}

SampleLogWriter::~SampleLogWriter() { close(); }

void SampleLogWriter::format_path(std::uint64_t index) {
  if (index == 0) {
    current_path_.assign(first_path_);
    return;
  }
  char digits[24];
  const auto [end, ec] = std::to_chars(digits, digits + sizeof digits, index);
  (void)ec;  // 24 characters hold any u64
  current_path_.assign(base_);
  current_path_.push_back('.');
  current_path_.append(digits, static_cast<std::size_t>(end - digits));
  current_path_.append(kExtension);
}

// Creates file `index` (named in current_path_), writes and syncs the header. On failure
// nothing is left behind (the file is removed) and errno is returned.
int SampleLogWriter::open_file(std::uint64_t index, int* fd_out) {
  format_path(index);
  // The first file honours `overwrite`; rotated parts belong to this recording (the
  // constructor checked or removed what was there).
  const int flags = O_WRONLY | O_CREAT | O_CLOEXEC | ((index == 0 && !options_.overwrite) ? O_EXCL : O_TRUNC);
  const int fd = ::open(current_path_.c_str(), flags, 0666);
  if (fd < 0) return errno;
  int error = pwrite_all(fd, header_bytes_.data(), header_bytes_.size(), 0);
  if (error == 0 && options_.sync && ::fdatasync(fd) != 0) error = errno;
  if (error != 0) {
    ::close(fd);
    ::unlink(current_path_.c_str());
    return error;
  }
  if (options_.sync) {
    // Make the new directory entry durable too (best effort: not every file system can).
    const int dir = ::open(directory_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
      (void)::fsync(dir);
      ::close(dir);
    }
  }
  *fd_out = fd;
  return 0;
}

bool SampleLogWriter::open_next_file() {
  int fd = -1;
  const int error = open_file(index_ + 1, &fd);
  if (error != 0) {
    format_path(index_);
    fail(error);
    return false;
  }
  // The full file: sync it before letting go (a failure is counted; its data cannot be
  // rewritten from here).
  if (dirty_) sync_current();
  if (::close(fd_) != 0) fail(errno);
  fd_ = fd;
  ++index_;
  file_bytes_ = header_bytes_.size();
  dirty_ = false;
  must_rotate_ = false;
  ++stats_.files;
  stats_.bytes_written += header_bytes_.size();
  return true;
}

void SampleLogWriter::fail(int error) {
  ++stats_.write_errors;
  stats_.last_errno = error;
}

bool SampleLogWriter::write_chunk(std::size_t begin, std::size_t end) {
  // At the committed end of the file: after a failed (possibly partial) write the retry
  // rewrites the same bytes at the same place.
  if (const int error = pwrite_all(fd_, buffer_.get() + begin, end - begin, file_bytes_); error != 0) {
    fail(error);
    return false;
  }
  dirty_ = true;
  return true;
}

bool SampleLogWriter::sync_current() {
  if (!options_.sync || !dirty_) return true;
  dirty_ = false;
  if (::fdatasync(fd_) != 0) {
    fail(errno);
    return false;
  }
  return true;
}

bool SampleLogWriter::append(const Sample& sample) {
  if (closed_) {
    ++stats_.samples_dropped;
    return false;
  }
  const std::size_t bytes = sample_record_bytes(sample);
  if (used_ + bytes > options_.buffer_bytes) {
    if (!failing_) flush();
    if (used_ + bytes > options_.buffer_bytes) {
      ++stats_.samples_dropped;
      return false;
    }
  }
  used_ += encode_sample_record(sample, buffer_.get() + used_);
  ++buffered_samples_;
  ++stats_.samples_appended;
  if (!failing_ && used_ > options_.flush_bytes) flush();
  return true;
}

bool SampleLogWriter::flush() {
  if (closed_) return false;
  if (have_now_) last_flush_time_ = last_now_;
  bool ok = true;
  bool wrote = false;
  std::size_t pos = 0;
  while (pos < used_) {
    if (must_rotate_ && !open_next_file()) {
      ok = false;
      break;
    }
    // The whole records from `pos` that still fit into the current file.
    const std::uint64_t room = options_.max_file_bytes == 0 ? std::numeric_limits<std::uint64_t>::max()
                               : options_.max_file_bytes > file_bytes_ ? options_.max_file_bytes - file_bytes_
                                                                       : 0;
    std::size_t end = pos;
    std::uint64_t samples = 0;
    while (end < used_) {
      const std::size_t size = kRecordOverheadBytes + detail::get_u32(buffer_.get() + end);
      const bool fits = (end - pos) + size <= room;
      const bool alone = end == pos && file_bytes_ == header_bytes_.size();  // an empty file takes
      if (!fits && !alone) break;                                             // one record, any size
      ++samples;  // the buffer holds sample records only
      end += size;
      if (!fits) break;
    }
    if (end == pos) {
      must_rotate_ = true;  // full: the next round opens the next file
      continue;
    }
    if (!write_chunk(pos, end)) {
      ok = false;
      break;
    }
    wrote = true;
    file_bytes_ += end - pos;
    stats_.bytes_written += end - pos;
    stats_.samples_written += samples;
    buffered_samples_ -= samples;
    pos = end;
  }
  if (pos > 0) {
    std::memmove(buffer_.get(), buffer_.get() + pos, used_ - pos);
    used_ -= pos;
  }
  if (!sync_current()) ok = false;
  if (ok && wrote) ++stats_.flushes;
  failing_ = !ok;
  return ok;
}

bool SampleLogWriter::maybe_flush(double now) {
  if (closed_) return false;
  last_now_ = now;
  if (!have_now_ || used_ == 0) {
    // Nothing waiting (or the first call): the interval starts now.
    have_now_ = true;
    last_flush_time_ = now;
    if (used_ == 0) return true;
  }
  const bool big = !failing_ && used_ > options_.flush_bytes;
  if (big || now - last_flush_time_ > options_.flush_interval) return flush();
  return true;
}

bool SampleLogWriter::close() {
  if (closed_) return true;
  bool ok = flush();
  if (used_ > 0) {
    stats_.samples_dropped += buffered_samples_;
    // A failed write may have left part of a record behind the committed end.
    (void)::ftruncate(fd_, static_cast<off_t>(file_bytes_));
    used_ = 0;
    buffered_samples_ = 0;
    ok = false;
  }
  if (fd_ >= 0) {
    if (::close(fd_) != 0) {
      fail(errno);
      ok = false;
    }
    fd_ = -1;
  }
  closed_ = true;
  return ok;
}

}  // namespace posefair::formats
