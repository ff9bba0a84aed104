// The sample log reader: header checks, record by record reading up to the first record that
// is not whole and intact. See sample_log.hpp and docs/recording.md.
#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <set>
#include <system_error>
#include <utility>

#include "posefair/formats/sample_log.hpp"

namespace posefair::formats {

namespace {

using detail::get_u16;
using detail::get_u32;
using detail::get_u64;

double get_f64(const unsigned char* p) { return std::bit_cast<double>(get_u64(p)); }

std::string hex32(std::uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", static_cast<unsigned>(v));
  return text;
}

std::string hex_bytes(const unsigned char* p, std::size_t n) {
  std::string out;
  char text[4];
  for (std::size_t i = 0; i < n; ++i) {
    std::snprintf(text, sizeof text, "%s%02x", i == 0 ? "" : " ", static_cast<unsigned>(p[i]));
    out += text;
  }
  return out;
}

std::string errno_text(int error) { return std::error_code(error, std::generic_category()).message(); }

}  // namespace

const StreamInfo* SampleLogHeader::find(std::uint32_t stream_id) const {
  for (const StreamInfo& s : streams) {
    if (s.id == stream_id) return &s;
  }
  return nullptr;
}

Sample decode_sample_body(const unsigned char* b) {
  Sample s;
  s.stream_id = get_u32(b + 0);
  s.sequence = get_u64(b + 4);
  s.time = get_f64(b + 12);
  s.device_time = get_f64(b + 20);
  s.receive_time = get_f64(b + 28);
  s.flags = get_u32(b + 36);
  s.orientation = Quat(get_f64(b + 40), get_f64(b + 48), get_f64(b + 56), get_f64(b + 64));
  s.position = Vec3(get_f64(b + 72), get_f64(b + 80), get_f64(b + 88));
  return s;
}

Sample decode_imu_sample_body(const unsigned char* b) {
  Sample s = decode_sample_body(b);
  const unsigned char* p = b + kSampleBodyBytes;
  for (Vec3* v : {&s.gyro, &s.accel, &s.mag})
    for (int k = 0; k < 3; ++k, p += 8) (*v)[k] = get_f64(p);
  return s;
}

// ---------------------------------------------------------------------------------------------
// SampleLogReader

SampleLogReader::SampleLogReader(const std::filesystem::path& path) : path_(path.string()) {
  file_ = std::fopen(path_.c_str(), "rbe");
  if (file_ == nullptr) throw SampleLogError(path_, std::nullopt, "cannot open: " + errno_text(errno));
  struct stat st {};
  if (::fstat(::fileno(file_), &st) != 0) {
    const int error = errno;
    std::fclose(file_);
    throw SampleLogError(path_, std::nullopt, "cannot stat: " + errno_text(error));
  }
  if (S_ISDIR(st.st_mode)) {
    std::fclose(file_);
    throw SampleLogError(path_, std::nullopt, "is a directory, not a sample log");
  }
  file_size_ = static_cast<std::uint64_t>(st.st_size);
  try {
    read_header();
  } catch (...) {
    std::fclose(file_);  // the destructor does not run for a constructor that throws
    file_ = nullptr;
    throw;
  }
}

void SampleLogReader::read_header() {
  auto bad = [&](std::optional<std::uint64_t> offset, const std::string& message) {
    throw SampleLogError(path_, offset, message);
  };

  std::vector<unsigned char> h(kSampleLogPreambleBytes);
  const std::size_t n = read_some(h.data(), h.size());
  const std::size_t magic_seen = std::min(n, sizeof kSampleLogMagic);
  if (std::memcmp(h.data(), kSampleLogMagic, magic_seen) != 0) {
    bad(0, "not a posefair sample log (bad magic: expected " + hex_bytes(kSampleLogMagic, sizeof kSampleLogMagic) +
               ", found " + hex_bytes(h.data(), magic_seen) + ")");
  }
  if (n == 0) bad(std::nullopt, "empty file: no sample log header");
  if (n < kSampleLogPreambleBytes) {
    bad(0, "truncated header (" + std::to_string(n) + " bytes present, a header has at least " +
               std::to_string(kSampleLogMinHeaderBytes) + ")");
  }
  const std::uint16_t version = get_u16(h.data() + 8);
  if (version != kSampleLogVersion) {
    bad(8, "unsupported format version " + std::to_string(version) + " (this reader reads version " +
               std::to_string(kSampleLogVersion) + ")");
  }
  const std::size_t header_length = get_u16(h.data() + 10);
  if (header_length < kSampleLogMinHeaderBytes) {
    bad(10, "header length " + std::to_string(header_length) + " is too small (at least " +
                std::to_string(kSampleLogMinHeaderBytes) + ")");
  }
  h.resize(header_length);
  const std::size_t rest = read_some(h.data() + kSampleLogPreambleBytes, header_length - kSampleLogPreambleBytes);
  if (rest < header_length - kSampleLogPreambleBytes) {
    bad(0, "truncated header (expected " + std::to_string(header_length) + " bytes, " +
               std::to_string(kSampleLogPreambleBytes + rest) + " present)");
  }
  const std::uint32_t stored = get_u32(h.data() + header_length - 4);
  const std::uint32_t computed = detail::crc32(h.data(), header_length - 4);
  if (stored != computed) {
    bad(header_length - 4, "header CRC mismatch (stored " + hex32(stored) + ", computed " + hex32(computed) + ")");
  }

  // The stream table; anything between its end and the CRC is reserved and skipped.
  const std::size_t table_end = header_length - 4;
  std::size_t p = kSampleLogPreambleBytes;
  if (p + 2 > table_end) bad(p, "malformed stream table (no stream count)");
  const std::size_t count = get_u16(h.data() + p);
  p += 2;
  std::set<std::uint32_t> ids;
  header_.version = version;
  header_.streams.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t entry = p;
    auto overrun = [&] {
      bad(entry, "malformed stream table (entry " + std::to_string(i) + " of " + std::to_string(count) +
                     " runs past the header's end)");
    };
    StreamInfo s;
    if (p + 6 > table_end) overrun();
    s.id = get_u32(h.data() + p);
    std::size_t len = get_u16(h.data() + p + 4);
    p += 6;
    if (p + len + 2 > table_end) overrun();
    s.name.assign(reinterpret_cast<const char*>(h.data() + p), len);
    p += len;
    len = get_u16(h.data() + p);
    p += 2;
    if (p + len > table_end) overrun();
    s.source.assign(reinterpret_cast<const char*>(h.data() + p), len);
    p += len;
    if (!ids.insert(s.id).second) {
      bad(entry, "malformed stream table (stream id " + std::to_string(s.id) + " appears twice)");
    }
    header_.streams.push_back(std::move(s));
  }
  offset_ = header_length;
  stats_.bytes = header_length;
}

SampleLogReader::~SampleLogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

std::size_t SampleLogReader::read_some(unsigned char* out, std::size_t n) {
  std::size_t got = 0;
  while (got < n) {
    const std::size_t r = std::fread(out + got, 1, n - got, file_);
    if (r == 0) break;
    got += r;
  }
  return got;
}

void SampleLogReader::problem(std::uint64_t offset, std::string message) {
  done_ = true;
  SampleLogProblem p;
  p.path = path_;
  p.offset = offset;
  struct stat st {};
  std::uint64_t size = file_size_;
  if (::fstat(::fileno(file_), &st) == 0) size = std::max<std::uint64_t>(size, static_cast<std::uint64_t>(st.st_size));
  p.unread_bytes = size > offset ? size - offset : 0;

  // A tail of zeros is what a crash can leave when the file system had extended the file but
  // not yet written the data: say so instead of "CRC mismatch".
  if (p.unread_bytes > 0 && p.unread_bytes <= (1u << 20) && std::fseek(file_, static_cast<long>(offset), SEEK_SET) == 0) {
    std::vector<unsigned char> tail(static_cast<std::size_t>(p.unread_bytes));
    if (read_some(tail.data(), tail.size()) == tail.size() &&
        std::all_of(tail.begin(), tail.end(), [](unsigned char c) { return c == 0; })) {
      message = "zero-filled tail (" + std::to_string(p.unread_bytes) +
                " bytes of zeros, as a crash can leave before the data reached the disk)";
    }
  }
  p.message = path_ + ": offset " + std::to_string(offset) + ": " + message;
  stats_.problems.push_back(std::move(p));
}

bool SampleLogReader::next(Sample& out) {
  while (!done_) {
    const std::uint64_t start = offset_;
    unsigned char head[5];
    const std::size_t n = read_some(head, sizeof head);
    if (n == 0) {
      if (std::ferror(file_)) problem(start, "read error: " + errno_text(errno));
      done_ = true;
      return false;
    }
    if (n < 4) {
      problem(start, "truncated record (expected at least " + std::to_string(kRecordOverheadBytes) + " bytes, " +
                         std::to_string(n) + " present)");
      return false;
    }
    const std::uint32_t length = get_u32(head);
    const std::uint64_t expected = kRecordOverheadBytes + static_cast<std::uint64_t>(length);
    if (length > kMaxRecordBodyBytes) {
      problem(start, "record length " + std::to_string(length) + " exceeds the limit of " +
                         std::to_string(kMaxRecordBodyBytes) + " bytes (corrupt length field)");
      return false;
    }
    std::size_t present = n;
    if (n == 5) {
      // body_ = type, body, crc: the CRC covers body_[0, 1 + length).
      body_.resize(1 + length + 4);
      body_[0] = head[4];
      present += read_some(body_.data() + 1, length + 4);
    }
    if (present < expected) {
      if (std::ferror(file_)) {
        problem(start, "read error: " + errno_text(errno));
      } else {
        problem(start, "truncated record (expected " + std::to_string(expected) + " bytes, " +
                           std::to_string(present) + " present)");
      }
      return false;
    }
    const std::uint32_t stored = get_u32(body_.data() + 1 + length);
    const std::uint32_t computed = detail::crc32(body_.data(), 1 + length);
    if (stored != computed) {
      problem(start, "record CRC mismatch (stored " + hex32(stored) + ", computed " + hex32(computed) + ")");
      return false;
    }
    const auto type = static_cast<RecordType>(body_[0]);
    if (type == RecordType::Sample && length < kSampleBodyBytes) {
      problem(start, "sample record of " + std::to_string(length) + " bytes (a sample body has " +
                         std::to_string(kSampleBodyBytes) + ")");
      return false;
    }
    if (type == RecordType::ImuSample && length < kImuSampleBodyBytes) {
      problem(start, "IMU sample record of " + std::to_string(length) + " bytes (an IMU sample body has " +
                         std::to_string(kImuSampleBodyBytes) + ")");
      return false;
    }
    offset_ += expected;
    ++stats_.records;
    stats_.bytes += expected;
    if (type == RecordType::Sample || type == RecordType::ImuSample) {
      // Longer bodies are a later version's additions: the first 96 (168) bytes are as here.
      out = type == RecordType::Sample ? decode_sample_body(body_.data() + 1) : decode_imu_sample_body(body_.data() + 1);
      ++stats_.samples;
      if (header_.find(out.stream_id) == nullptr) ++stats_.unknown_stream_samples;
      return true;
    }
    ++stats_.unknown_records;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------

bool is_sample_log_file(const std::filesystem::path& path) {
  if (path.extension() == ".pflog") return true;
  std::FILE* f = std::fopen(path.c_str(), "rbe");
  if (f == nullptr) return false;
  unsigned char head[sizeof kSampleLogMagic] = {};
  const std::size_t n = std::fread(head, 1, sizeof head, f);
  std::fclose(f);
  return n == sizeof head && std::memcmp(head, kSampleLogMagic, sizeof head) == 0;
}

SampleLogContents read_sample_log(const std::filesystem::path& path) {
  SampleLogReader reader(path);
  SampleLogContents out;
  out.header = reader.header();
  out.samples.reserve(static_cast<std::size_t>(reader.file_size() / kSampleRecordBytes));
  Sample s;
  while (reader.next(s)) out.samples.push_back(s);
  out.stats = reader.stats();
  return out;
}

SampleLogContents read_sample_log_set(const std::filesystem::path& first) {
  const std::vector<std::filesystem::path> files = sample_log_files(first);
  SampleLogContents out;
  for (std::size_t i = 0; i < files.size(); ++i) {
    SampleLogContents part = read_sample_log(files[i]);
    if (i == 0) {
      out.header = std::move(part.header);
    } else if (!(part.header == out.header)) {
      throw SampleLogError(files[i].string(), std::nullopt,
                           "its header differs from that of " + first.string() + " (not part of the same recording)");
    }
    out.samples.insert(out.samples.end(), part.samples.begin(), part.samples.end());
    out.stats.records += part.stats.records;
    out.stats.samples += part.stats.samples;
    out.stats.unknown_records += part.stats.unknown_records;
    out.stats.unknown_stream_samples += part.stats.unknown_stream_samples;
    out.stats.bytes += part.stats.bytes;
    for (SampleLogProblem& p : part.stats.problems) out.stats.problems.push_back(std::move(p));
  }
  return out;
}

}  // namespace posefair::formats
