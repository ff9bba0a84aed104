// The sample log: byte layout, bit-exact round trips, rotation, the flush policy, write
// failures, and the reader's answers to truncation, corruption and bad headers.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <utility>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "posefair/formats/sample_log.hpp"
#include "sample_log_test_support.hpp"

namespace posefair::formats {
namespace {

namespace fs = std::filesystem;
using testing::bit_identical;
using testing::make_samples;
using testing::ScratchDir;
using testing::slurp;
using testing::spit;

SampleLogHeader three_streams() {
  SampleLogHeader h;
  h.streams = {{10, "head", "serial:/dev/ttyUSB0 bno085"},
               {11, "Hand (links) \xc3\xbc", "can:vcan0 id 0x120"},
               {12, "", ""}};
  return h;
}

SampleLogWriterOptions quick() {
  SampleLogWriterOptions o;
  o.sync = false;  // tmpfs or not: the tests do not need the disk
  return o;
}

// Writes `samples` to a fresh log and returns its bytes.
std::vector<unsigned char> write_log(const fs::path& path, const std::vector<Sample>& samples,
                                     SampleLogWriterOptions options = quick()) {
  SampleLogWriter w(path, three_streams(), options);
  for (const Sample& s : samples) EXPECT_TRUE(w.append(s));
  EXPECT_TRUE(w.close());
  return slurp(path);
}

std::size_t header_size() { return encode_sample_log_header(three_streams()).size(); }

TEST(SampleLog, Crc32IsZlibs) {
  const char* check = "123456789";
  EXPECT_EQ(detail::crc32(reinterpret_cast<const unsigned char*>(check), 9), 0xCBF43926u);
}

TEST(SampleLog, HeaderBytesAreAsDocumented) {
  SampleLogHeader h;
  h.streams = {{7, "head", "imu"}};
  const std::vector<unsigned char> b = encode_sample_log_header(h);
  const std::vector<unsigned char> expected_prefix = {
      'P', 'F', 'L', 'O', 'G', 0, 0, 1,  // magic
      1, 0,                              // version 1
      33, 0,                             // header length: 12 + 2 + (4 + 2 + 4 + 2 + 3) + 4
      1, 0,                              // one stream
      7, 0, 0, 0,                        // id 7
      4, 0, 'h', 'e', 'a', 'd',          // name
      3, 0, 'i', 'm', 'u'};              // source
  ASSERT_EQ(b.size(), 33u);
  EXPECT_EQ(std::vector<unsigned char>(b.begin(), b.end() - 4), expected_prefix);
  EXPECT_EQ(detail::get_u32(b.data() + 29), detail::crc32(b.data(), 29));
}

TEST(SampleLog, SampleRecordBytesAreAsDocumented) {
  Sample s;
  s.stream_id = 0x01020304;
  s.sequence = 0x1112131415161718ull;
  s.time = 1.5;
  s.device_time = -2.0;
  s.receive_time = 3.25;
  s.flags = kHasPosition | kHasDeviceTime;
  s.orientation = Quat(0.5, -0.5, 0.5, -0.5);
  s.position = Vec3(1.0, 2.0, 3.0);
  unsigned char r[kSampleRecordBytes];
  encode_sample_record(s, r);
  EXPECT_EQ(kSampleRecordBytes, 105u);
  EXPECT_EQ(detail::get_u32(r), 96u);   // body length
  EXPECT_EQ(r[4], 1);                   // type: sample
  const unsigned char* b = r + 5;
  EXPECT_EQ(b[0], 0x04);                // little-endian stream id
  EXPECT_EQ(b[3], 0x01);
  EXPECT_EQ(b[4], 0x18);                // sequence
  EXPECT_EQ(b[11], 0x11);
  EXPECT_EQ(testing::bits(1.5), detail::get_u64(b + 12));
  EXPECT_EQ(testing::bits(-2.0), detail::get_u64(b + 20));
  EXPECT_EQ(testing::bits(3.25), detail::get_u64(b + 28));
  EXPECT_EQ(detail::get_u32(b + 36), 3u);
  EXPECT_EQ(testing::bits(0.5), detail::get_u64(b + 40));   // w first
  EXPECT_EQ(testing::bits(-0.5), detail::get_u64(b + 48));  // x
  EXPECT_EQ(testing::bits(3.0), detail::get_u64(b + 88));   // pz
  EXPECT_EQ(detail::get_u32(r + 101), detail::crc32(r + 4, 97));
  EXPECT_TRUE(bit_identical(decode_sample_body(b), s));
}

// The two examples of docs/recording.md, byte for byte.
TEST(SampleLog, TheDocumentedExamplesAreWhatTheEncoderWrites) {
  SampleLogHeader h;
  h.streams = {{7, "head", "imu"}};
  const std::vector<unsigned char> header = {0x50, 0x46, 0x4c, 0x4f, 0x47, 0x00, 0x00, 0x01, 0x01, 0x00, 0x21,
                                             0x00, 0x01, 0x00, 0x07, 0x00, 0x00, 0x00, 0x04, 0x00, 0x68, 0x65,
                                             0x61, 0x64, 0x03, 0x00, 0x69, 0x6d, 0x75, 0x59, 0x44, 0xa7, 0x4a};
  EXPECT_EQ(encode_sample_log_header(h), header);

  Sample s;
  s.stream_id = 7;
  s.sequence = 42;
  s.time = 1.5;
  s.device_time = 0.0;
  s.receive_time = 1234.5;
  s.flags = kHasPosition;
  s.orientation = Quat(1.0, 0.0, 0.0, 0.0);
  s.position = Vec3(0.25, -1.0, 2.0);
  std::vector<unsigned char> expected(kSampleRecordBytes, 0);
  const std::pair<std::size_t, std::vector<unsigned char>> nonzero[] = {
      {0x00, {0x60}}, {0x04, {0x01, 0x07}}, {0x09, {0x2a}}, {0x17, {0xf8, 0x3f}}, {0x26, {0x4a, 0x93, 0x40, 0x01}},
      {0x33, {0xf0, 0x3f}}, {0x53, {0xd0, 0x3f}}, {0x5b, {0xf0, 0xbf}}, {0x64, {0x40, 0x1e, 0x04, 0x9e, 0xe0}}};
  for (const auto& [at, bytes] : nonzero) std::copy(bytes.begin(), bytes.end(), expected.begin() + static_cast<std::ptrdiff_t>(at));
  std::vector<unsigned char> r(kSampleRecordBytes);
  encode_sample_record(s, r.data());
  EXPECT_EQ(r, expected);
}

// docs/recording.md, the IMU sample example (type 2): stream 7, sequence 43, time 2, receive
// time 1235, flags kHasGyro | kHasAccel | kNoOrientation, gyro (0.5, -0.25, 0.125), accel
// (0, 0, 9.8125). Bytes computed for the document independently of the encoder.
TEST(SampleLog, TheDocumentedImuSampleIsWhatTheEncoderWrites) {
  Sample s;
  s.stream_id = 7;
  s.sequence = 43;
  s.time = 2.0;
  s.receive_time = 1235.0;
  s.flags = kHasGyro | kHasAccel | kNoOrientation;
  s.gyro = Vec3(0.5, -0.25, 0.125);
  s.accel = Vec3(0, 0, 9.8125);
  std::vector<unsigned char> expected(kImuSampleRecordBytes, 0);
  const std::pair<std::size_t, std::vector<unsigned char>> nonzero[] = {
      {0x00, {0xa8}}, {0x04, {0x02, 0x07}}, {0x09, {0x2b}}, {0x18, {0x40}}, {0x26, {0x4c, 0x93, 0x40, 0xb0}},
      {0x33, {0xf0, 0x3f}}, {0x6b, {0xe0, 0x3f}}, {0x73, {0xd0, 0xbf}}, {0x7b, {0xc0, 0x3f}},
      {0x92, {0xa0, 0x23, 0x40}}, {0xad, {0x97, 0x76, 0x2f, 0x51}}};
  for (const auto& [at, bytes] : nonzero) std::copy(bytes.begin(), bytes.end(), expected.begin() + static_cast<std::ptrdiff_t>(at));
  EXPECT_EQ(sample_record_type(s), RecordType::ImuSample);
  EXPECT_EQ(sample_record_bytes(s), 177u);
  std::vector<unsigned char> r(kImuSampleRecordBytes);
  EXPECT_EQ(encode_sample_record(s, r.data()), 177u);
  EXPECT_EQ(r, expected);
  EXPECT_TRUE(bit_identical(decode_imu_sample_body(r.data() + 5), s));
  // Without readings (and with an orientation) a sample is the 105-byte type 1 record as before.
  s.flags = kHasDeviceTime;
  EXPECT_EQ(sample_record_type(s), RecordType::Sample);
  EXPECT_EQ(encode_sample_record(s, r.data()), kSampleRecordBytes);
}

// A log written before IMU sample records existed (the documented header and sample example,
// the bytes an old writer wrote) reads as it always did; and an IMU sample record with a longer
// body (a later version's additions) reads its first 168 bytes, one with a shorter body stops
// the read with a problem.
TEST(SampleLog, OldLogsReadAndImuRecordBodiesAreChecked) {
  ScratchDir dir;
  const std::vector<unsigned char> old_log = {
      0x50, 0x46, 0x4c, 0x4f, 0x47, 0x00, 0x00, 0x01, 0x01, 0x00, 0x21, 0x00, 0x01, 0x00, 0x07, 0x00, 0x00,
      0x00, 0x04, 0x00, 0x68, 0x65, 0x61, 0x64, 0x03, 0x00, 0x69, 0x6d, 0x75, 0x59, 0x44, 0xa7, 0x4a, 0x60,
      0x00, 0x00, 0x00, 0x01, 0x07, 0x00, 0x00, 0x00, 0x2a, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0xf8, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x4a, 0x93, 0x40, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xf0,
      0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xd0, 0x3f, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0xf0, 0xbf, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40, 0x1e, 0x04,
      0x9e, 0xe0};  // docs/recording.md's header and sample record examples
  spit(dir / "old.pflog", old_log);
  const SampleLogContents old = read_sample_log(dir / "old.pflog");
  ASSERT_EQ(old.samples.size(), 1u);
  EXPECT_TRUE(old.stats.problems.empty());
  EXPECT_EQ(old.samples[0].flags, std::uint32_t{kHasPosition});
  EXPECT_EQ(old.samples[0].position, Vec3(0.25, -1.0, 2.0));
  EXPECT_EQ(old.samples[0].gyro, Vec3::Zero());

  Sample imu = make_samples(1)[0];
  imu.flags |= kHasMag;
  imu.mag = Vec3(1, 2, 3);
  std::vector<unsigned char> rec(kImuSampleRecordBytes);
  encode_sample_record(imu, rec.data());
  const auto with_body = [&](std::size_t body) {  // the record with its body cut or padded, CRC redone
    std::vector<unsigned char> r(rec.begin(), rec.begin() + 5 + static_cast<std::ptrdiff_t>(std::min(body, kImuSampleBodyBytes)));
    r.resize(5 + body, 0xEE);
    detail::put_u32(r.data(), static_cast<std::uint32_t>(body));
    r.resize(r.size() + 4);
    detail::put_u32(r.data() + 5 + body, detail::crc32(r.data() + 4, 1 + body));
    return r;
  };
  std::vector<unsigned char> longer = old_log;
  for (unsigned char b : with_body(kImuSampleBodyBytes + 16)) longer.push_back(b);
  spit(dir / "longer.pflog", longer);
  const SampleLogContents l = read_sample_log(dir / "longer.pflog");
  ASSERT_EQ(l.samples.size(), 2u);
  EXPECT_TRUE(bit_identical(l.samples[1], imu));
  std::vector<unsigned char> shorter = old_log;
  for (unsigned char b : with_body(kSampleBodyBytes)) shorter.push_back(b);
  spit(dir / "shorter.pflog", shorter);
  const SampleLogContents sh = read_sample_log(dir / "shorter.pflog");
  EXPECT_EQ(sh.samples.size(), 1u);
  ASSERT_EQ(sh.stats.problems.size(), 1u);
  EXPECT_NE(sh.stats.problems[0].message.find("IMU sample record of 96 bytes (an IMU sample body has 168)"), std::string::npos)
      << sh.stats.problems[0].message;
}

TEST(SampleLog, RoundTripIsBitIdentical) {
  ScratchDir dir;
  std::vector<Sample> samples = make_samples(1000);
  // Values a careless encoder would lose.
  samples[3].time = -0.0;
  samples[4].device_time = std::numeric_limits<double>::denorm_min();
  samples[5].receive_time = std::bit_cast<double>(0x7ff8dead'beef0001ull);  // NaN with a payload
  samples[6].orientation = Quat(2.0, 0.0, 0.0, 0.0);                        // not unit: as given
  samples[7].position = Vec3(std::numeric_limits<double>::infinity(), -1e308, 1e-300);
  samples[8].sequence = std::numeric_limits<std::uint64_t>::max();
  samples[9].flags = 0xFFFF'FFFFu;  // unknown bits too
  samples[10].stream_id = 99;       // not in the stream table: kept, counted
  samples[9].gyro = Vec3(1, 2, 3);  // (its flags say it has every reading: an IMU sample record)
  samples[11].flags |= kHasGyro | kHasAccel | kHasMag;
  samples[11].gyro = Vec3(-0.0, std::bit_cast<double>(0x7ff8dead'beef0002ull), 1e-300);
  samples[11].accel = Vec3(0.1, 0.2, 9.81);
  samples[11].mag = Vec3(20, -5, -40);
  samples[12].flags |= kNoOrientation | kHasAccel;  // raw-only
  samples[12].accel = Vec3(0, 0, 9.81);
  const fs::path path = dir / "run.pflog";
  const std::vector<unsigned char> bytes = write_log(path, samples);
  EXPECT_EQ(bytes.size(), header_size() + (samples.size() - 3) * kSampleRecordBytes + 3 * kImuSampleRecordBytes);

  const SampleLogContents log = read_sample_log(path);
  EXPECT_EQ(log.header, three_streams());
  ASSERT_EQ(log.samples.size(), samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) ASSERT_TRUE(bit_identical(log.samples[i], samples[i])) << i;
  EXPECT_TRUE(log.stats.problems.empty());
  EXPECT_EQ(log.stats.samples, samples.size());
  EXPECT_EQ(log.stats.records, samples.size());
  EXPECT_EQ(log.stats.unknown_records, 0u);
  EXPECT_EQ(log.stats.unknown_stream_samples, 1u);
  EXPECT_EQ(log.stats.bytes, bytes.size());
}

TEST(SampleLog, AnEmptyLogHasAHeaderAndNoSamples) {
  ScratchDir dir;
  const fs::path path = dir / "empty.pflog";
  SampleLogHeader none;
  { SampleLogWriter w(path, none, quick()); }
  EXPECT_EQ(fs::file_size(path), kSampleLogMinHeaderBytes);
  const SampleLogContents log = read_sample_log(path);
  EXPECT_TRUE(log.header.streams.empty());
  EXPECT_TRUE(log.samples.empty());
  EXPECT_TRUE(log.stats.problems.empty());
}

TEST(SampleLog, RotationNaming) {
  EXPECT_EQ(sample_log_part_path("a/run.pflog", 0), fs::path("a/run.pflog"));
  EXPECT_EQ(sample_log_part_path("a/run.pflog", 1), fs::path("a/run.1.pflog"));
  EXPECT_EQ(sample_log_part_path("a/run.pflog", 12), fs::path("a/run.12.pflog"));
  EXPECT_EQ(sample_log_part_path("run.log", 2), fs::path("run.log.2.pflog"));
  EXPECT_EQ(sample_log_part_path(".pflog", 1), fs::path(".pflog.1.pflog"));
}

// Rotation with every flush pattern: flushes per few samples, one big flush that spans many
// files, and per-sample flushes.
TEST(SampleLog, RotationSplitsIntoCompleteFilesThatReadBackInOrder) {
  const std::vector<Sample> samples = make_samples(95);
  const std::uint64_t max_bytes = header_size() + 10 * kSampleRecordBytes;  // ten samples a file
  struct Pattern {
    const char* name;
    std::size_t buffer, flush;
  };
  for (const Pattern& p : {Pattern{"every few", 4096, 300}, Pattern{"one big flush", 64 * 1024, 64 * 1024},
                           Pattern{"every sample", 4096, 0}}) {
    SCOPED_TRACE(p.name);
    ScratchDir dir;
    const fs::path first = dir / "run.pflog";
    SampleLogWriterOptions o = quick();
    o.buffer_bytes = p.buffer;
    o.flush_bytes = p.flush;
    o.max_file_bytes = max_bytes;
    {
      SampleLogWriter w(first, three_streams(), o);
      for (const Sample& s : samples) ASSERT_TRUE(w.append(s));
      EXPECT_TRUE(w.flush());
      EXPECT_EQ(w.current_index(), 9u);
      EXPECT_EQ(w.current_path(), (dir / "run.9.pflog").string());
      EXPECT_EQ(w.stats().files, 10u);
      EXPECT_EQ(w.stats().samples_written, 95u);
      EXPECT_TRUE(w.close());
    }
    const std::vector<fs::path> files = sample_log_files(first);
    ASSERT_EQ(files.size(), 10u);
    std::vector<Sample> all;
    for (std::size_t i = 0; i < files.size(); ++i) {
      EXPECT_EQ(files[i], sample_log_part_path(first, i));
      EXPECT_LE(fs::file_size(files[i]), max_bytes);
      const SampleLogContents part = read_sample_log(files[i]);  // each part stands alone
      EXPECT_EQ(part.header, three_streams());
      EXPECT_TRUE(part.stats.problems.empty());
      EXPECT_EQ(part.samples.size(), i < 9 ? 10u : 5u);
      all.insert(all.end(), part.samples.begin(), part.samples.end());
    }
    EXPECT_FALSE(fs::exists(dir / "run.10.pflog"));
    ASSERT_EQ(all.size(), samples.size());
    for (std::size_t i = 0; i < all.size(); ++i) ASSERT_TRUE(bit_identical(all[i], samples[i])) << i;
    const SampleLogContents set = read_sample_log_set(first);
    ASSERT_EQ(set.samples.size(), samples.size());
    for (std::size_t i = 0; i < all.size(); ++i) ASSERT_TRUE(bit_identical(set.samples[i], samples[i])) << i;
    EXPECT_EQ(set.stats.samples, 95u);
  }
}

TEST(SampleLog, ALimitBelowOneRecordStillStoresOneRecordPerFile) {
  ScratchDir dir;
  SampleLogWriterOptions o = quick();
  o.max_file_bytes = 1;
  const fs::path first = dir / "tiny.pflog";
  const std::vector<Sample> samples = make_samples(4);
  {
    SampleLogWriter w(first, three_streams(), o);
    for (const Sample& s : samples) w.append(s);
  }
  const std::vector<fs::path> files = sample_log_files(first);
  ASSERT_EQ(files.size(), 4u);
  for (const fs::path& f : files) EXPECT_EQ(fs::file_size(f), header_size() + kSampleRecordBytes);
  EXPECT_EQ(read_sample_log_set(first).samples.size(), 4u);
}

TEST(SampleLog, AnExistingRecordingIsKeptUnlessOverwriteIsSet) {
  ScratchDir dir;
  const fs::path first = dir / "run.pflog";
  SampleLogWriterOptions o = quick();
  o.max_file_bytes = header_size() + 2 * kSampleRecordBytes;
  write_log(first, make_samples(9), o);  // five files
  ASSERT_EQ(sample_log_files(first).size(), 5u);
  try {
    SampleLogWriter w(first, three_streams(), quick());
    FAIL() << "no error";
  } catch (const SampleLogError& e) {
    EXPECT_EQ(e.path(), first.string());
    EXPECT_NE(std::string(e.what()).find("exists already"), std::string::npos) << e.what();
  }
  fs::remove(first);  // an orphaned second part is refused too
  EXPECT_THROW(SampleLogWriter(first, three_streams(), quick()), SampleLogError);

  SampleLogWriterOptions replace = quick();
  replace.overwrite = true;
  write_log(first, make_samples(3), replace);
  EXPECT_EQ(sample_log_files(first).size(), 1u);  // the old parts are gone
  EXPECT_EQ(read_sample_log_set(first).samples.size(), 3u);
}

TEST(SampleLog, WriterErrorsAtOpenThrow) {
  ScratchDir dir;
  try {
    SampleLogWriter w(dir / "no" / "such" / "dir.pflog", three_streams(), quick());
    FAIL() << "no error";
  } catch (const SampleLogError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create the log: No such file or directory"), std::string::npos)
        << e.what();
  }
  SampleLogHeader dup;
  dup.streams = {{1, "a", ""}, {1, "b", ""}};
  EXPECT_THROW(SampleLogWriter(dir / "dup.pflog", dup, quick()), std::invalid_argument);
  SampleLogHeader huge;
  huge.streams = {{1, std::string(70000, 'x'), ""}};
  EXPECT_THROW(SampleLogWriter(dir / "huge.pflog", huge, quick()), std::invalid_argument);
  SampleLogWriterOptions bad = quick();
  bad.flush_bytes = bad.buffer_bytes + 1;
  EXPECT_THROW(SampleLogWriter(dir / "bad.pflog", three_streams(), bad), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "dup.pflog"));
}

TEST(SampleLog, FlushPolicyBySizeAndByTime) {
  ScratchDir dir;
  const fs::path path = dir / "policy.pflog";
  SampleLogWriterOptions o = quick();
  o.flush_bytes = 10 * kSampleRecordBytes;  // flush once more than ten samples wait
  o.flush_interval = 0.5;
  SampleLogWriter w(path, three_streams(), o);
  const std::vector<Sample> samples = make_samples(30);
  const auto on_disk = [&] { return (fs::file_size(path) - header_size()) / kSampleRecordBytes; };

  EXPECT_TRUE(w.maybe_flush(100.0));  // nothing buffered: the interval starts here
  for (int i = 0; i < 10; ++i) w.append(samples[static_cast<std::size_t>(i)]);
  EXPECT_EQ(on_disk(), 0u);
  EXPECT_EQ(w.buffered_bytes(), 10 * kSampleRecordBytes);
  w.append(samples[10]);  // eleven: over the size threshold
  EXPECT_EQ(on_disk(), 11u);
  EXPECT_EQ(w.buffered_bytes(), 0u);

  EXPECT_TRUE(w.maybe_flush(100.1));  // empty: interval restarts at 100.1
  w.append(samples[11]);
  EXPECT_TRUE(w.maybe_flush(100.5));
  EXPECT_EQ(on_disk(), 11u);  // 0.4 s: not yet
  EXPECT_TRUE(w.maybe_flush(100.65));
  EXPECT_EQ(on_disk(), 12u);  // 0.55 s since 100.1
  EXPECT_EQ(w.stats().flushes, 2u);
  EXPECT_EQ(w.stats().samples_written, 12u);
  EXPECT_EQ(w.stats().write_errors, 0u);

  w.append(samples[12]);
  EXPECT_TRUE(w.close());
  EXPECT_EQ(on_disk(), 13u);
  EXPECT_FALSE(w.append(samples[13]));  // closed: dropped and counted
  EXPECT_EQ(w.stats().samples_dropped, 1u);
  EXPECT_FALSE(w.flush());
}

// A file size limit (RLIMIT_FSIZE) makes write(2) fail with EFBIG part way through.
TEST(SampleLog, FailedWritesAreCountedAndNothingIsLostSilently) {
  ScratchDir dir;
  const fs::path path = dir / "limited.pflog";
  SampleLogWriterOptions o = quick();
  o.buffer_bytes = 4096;  // 39 samples
  o.flush_bytes = 1000;
  o.flush_interval = 1.0;
  SampleLogWriter w(path, three_streams(), o);
  const std::vector<Sample> samples = make_samples(200);

  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  struct sigaction ignore {}, previous{};
  ignore.sa_handler = SIG_IGN;
  ASSERT_EQ(::sigaction(SIGXFSZ, &ignore, &previous), 0);
  rlimit limited = old;
  const std::size_t fits = 25;
  limited.rlim_cur = header_size() + fits * kSampleRecordBytes + 50;  // 25.5 records: a partial write
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &limited), 0);

  std::size_t accepted = 0;
  for (const Sample& s : samples) accepted += w.append(s) ? 1 : 0;
  const bool flushed_while_limited = w.maybe_flush(10.0);  // starts the interval
  const bool retried_while_limited = w.maybe_flush(11.5);  // a retry: still failing
  const SampleLogWriterStats limited_stats = w.stats();

  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &old), 0);
  ASSERT_EQ(::sigaction(SIGXFSZ, &previous, nullptr), 0);

  EXPECT_FALSE(retried_while_limited);
  (void)flushed_while_limited;
  EXPECT_GT(limited_stats.write_errors, 0u);
  EXPECT_EQ(limited_stats.last_errno, EFBIG);
  EXPECT_EQ(limited_stats.samples_written, 20u);  // two flushes of ten, the third failed
  EXPECT_LT(accepted, samples.size());
  EXPECT_EQ(limited_stats.samples_appended, accepted);
  EXPECT_EQ(limited_stats.samples_dropped, samples.size() - accepted);

  // The disk is back: everything accepted reaches the file, in order, whole.
  EXPECT_TRUE(w.maybe_flush(13.0));
  EXPECT_TRUE(w.close());
  EXPECT_EQ(w.stats().samples_written, accepted);
  const SampleLogContents log = read_sample_log(path);
  EXPECT_TRUE(log.stats.problems.empty()) << log.stats.problems.front().message;
  ASSERT_EQ(log.samples.size(), accepted);
  for (std::size_t i = 0; i < accepted; ++i) ASSERT_TRUE(bit_identical(log.samples[i], samples[i])) << i;
}

// A process killed with samples in the buffer leaves a log of everything flushed before.
TEST(SampleLog, AKilledWriterLeavesAReadableLog) {
  ScratchDir dir;
  const fs::path path = dir / "killed.pflog";
  const std::vector<Sample> samples = make_samples(1000);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SampleLogWriterOptions o;
    o.flush_bytes = 10 * kSampleRecordBytes;  // flushes every 11 samples
    SampleLogWriter w(path, three_streams(), o);
    for (const Sample& s : samples) w.append(s);
    ::kill(::getpid(), SIGKILL);
    ::_exit(3);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  const SampleLogContents log = read_sample_log(path);
  EXPECT_TRUE(log.stats.problems.empty());
  ASSERT_EQ(log.samples.size(), 1000u / 11u * 11u);  // 990; the last 10 were in the buffer
  for (std::size_t i = 0; i < log.samples.size(); ++i) ASSERT_TRUE(bit_identical(log.samples[i], samples[i]));
}

// A crash mid-write: cut the file at every byte inside the last two records.
TEST(SampleLog, TruncatedTailReturnsEverythingBeforeAndSaysWhere) {
  ScratchDir dir;
  const std::vector<Sample> samples = make_samples(10);
  const std::vector<unsigned char> bytes = write_log(dir / "full.pflog", samples);
  const std::size_t h = header_size();
  const fs::path cut = dir / "cut.pflog";
  for (std::size_t size = h + 8 * kSampleRecordBytes; size < bytes.size(); ++size) {
    SCOPED_TRACE(size);
    spit(cut, std::vector<unsigned char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size)));
    const SampleLogContents log = read_sample_log(cut);
    const std::size_t whole = (size - h) / kSampleRecordBytes;
    ASSERT_EQ(log.samples.size(), whole);
    for (std::size_t i = 0; i < whole; ++i) ASSERT_TRUE(bit_identical(log.samples[i], samples[i]));
    const std::size_t record_start = h + whole * kSampleRecordBytes;
    const std::size_t present = size - record_start;
    if (present == 0) {
      EXPECT_TRUE(log.stats.problems.empty());  // cut at a record boundary: a clean file
      continue;
    }
    ASSERT_EQ(log.stats.problems.size(), 1u);
    const SampleLogProblem& p = log.stats.problems[0];
    EXPECT_EQ(p.offset, record_start);
    EXPECT_EQ(p.unread_bytes, present);
    EXPECT_EQ(p.path, cut.string());
    const std::string expected =
        present < 4 ? cut.string() + ": offset " + std::to_string(record_start) +
                          ": truncated record (expected at least 9 bytes, " + std::to_string(present) + " present)"
                    : cut.string() + ": offset " + std::to_string(record_start) + ": truncated record (expected 105 bytes, " +
                          std::to_string(present) + " present)";
    EXPECT_EQ(p.message, expected);
    EXPECT_EQ(log.stats.bytes, record_start);
  }
}

TEST(SampleLog, ACorruptedByteStopsTheReadAtItsRecord) {
  ScratchDir dir;
  const std::vector<Sample> samples = make_samples(10);
  const std::vector<unsigned char> bytes = write_log(dir / "good.pflog", samples);
  const std::size_t start = header_size() + 5 * kSampleRecordBytes;  // the sixth record
  const fs::path bad = dir / "bad.pflog";
  for (std::size_t at = start; at < start + kSampleRecordBytes; ++at) {
    SCOPED_TRACE(at - start);
    std::vector<unsigned char> damaged = bytes;
    damaged[at] ^= 0x10;
    spit(bad, damaged);
    const SampleLogContents log = read_sample_log(bad);
    ASSERT_EQ(log.samples.size(), 5u);  // before it, and nothing after it
    for (std::size_t i = 0; i < 5; ++i) ASSERT_TRUE(bit_identical(log.samples[i], samples[i]));
    ASSERT_EQ(log.stats.problems.size(), 1u);
    const SampleLogProblem& p = log.stats.problems[0];
    EXPECT_EQ(p.offset, start);
    EXPECT_EQ(p.unread_bytes, bytes.size() - start);
    if (at >= start + 4) {  // the type, the body or the CRC: the CRC catches it
      EXPECT_EQ(p.message.find(bad.string() + ": offset " + std::to_string(start) + ": record CRC mismatch (stored 0x"), 0u)
          << p.message;
    }  // a changed length field reads a different span: a CRC mismatch or a bad length
  }
}

// A record is: u32 length, u8 type, body, u32 crc of type + body.
std::vector<unsigned char> record(std::uint8_t type, const std::vector<unsigned char>& body) {
  std::vector<unsigned char> r(kRecordOverheadBytes + body.size());
  detail::put_u32(r.data(), static_cast<std::uint32_t>(body.size()));
  r[4] = type;
  if (!body.empty()) std::memcpy(r.data() + 5, body.data(), body.size());
  detail::put_u32(r.data() + 5 + body.size(), detail::crc32(r.data() + 4, 1 + body.size()));
  return r;
}

TEST(SampleLog, UnknownRecordKindsAreSkippedAndCounted) {
  ScratchDir dir;
  const std::vector<Sample> samples = make_samples(4);
  std::vector<unsigned char> bytes = write_log(dir / "a.pflog", samples);
  const auto marker = record(42, {'m', 'a', 'r', 'k', 'e', 'r', '!'});
  const auto empty = record(200, {});
  const std::size_t at = header_size() + 2 * kSampleRecordBytes;
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at), marker.begin(), marker.end());
  bytes.insert(bytes.end(), empty.begin(), empty.end());
  spit(dir / "b.pflog", bytes);
  const SampleLogContents log = read_sample_log(dir / "b.pflog");
  ASSERT_EQ(log.samples.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_TRUE(bit_identical(log.samples[i], samples[i]));
  EXPECT_EQ(log.stats.unknown_records, 2u);
  EXPECT_EQ(log.stats.records, 6u);
  EXPECT_TRUE(log.stats.problems.empty());
}

TEST(SampleLog, ImplausibleAndShortRecordsAreReported) {
  ScratchDir dir;
  const std::vector<unsigned char> good = write_log(dir / "a.pflog", make_samples(2));
  {
    std::vector<unsigned char> bytes = good;
    const auto short_sample = record(1, std::vector<unsigned char>(50, 0));
    bytes.insert(bytes.end(), short_sample.begin(), short_sample.end());
    spit(dir / "short.pflog", bytes);
    const SampleLogContents log = read_sample_log(dir / "short.pflog");
    EXPECT_EQ(log.samples.size(), 2u);
    ASSERT_EQ(log.stats.problems.size(), 1u);
    EXPECT_EQ(log.stats.problems[0].offset, good.size());
    EXPECT_NE(log.stats.problems[0].message.find("sample record of 50 bytes (a sample body has 96)"), std::string::npos);
  }
  {
    std::vector<unsigned char> bytes = good;
    const unsigned char huge[] = {0xff, 0xff, 0xff, 0x7f, 1, 0, 0, 0, 0, 0, 0, 0};
    bytes.insert(bytes.end(), std::begin(huge), std::end(huge));
    spit(dir / "huge.pflog", bytes);
    const SampleLogContents log = read_sample_log(dir / "huge.pflog");
    EXPECT_EQ(log.samples.size(), 2u);
    ASSERT_EQ(log.stats.problems.size(), 1u);
    EXPECT_EQ(log.stats.problems[0].message,
              (dir / "huge.pflog").string() + ": offset " + std::to_string(good.size()) +
                  ": record length 2147483647 exceeds the limit of 1048576 bytes (corrupt length field)");
    EXPECT_EQ(log.stats.problems[0].unread_bytes, sizeof huge);
  }
  {
    std::vector<unsigned char> bytes = good;
    bytes.resize(bytes.size() + 4096, 0);  // what a crash can leave on some file systems
    spit(dir / "zeros.pflog", bytes);
    const SampleLogContents log = read_sample_log(dir / "zeros.pflog");
    EXPECT_EQ(log.samples.size(), 2u);
    ASSERT_EQ(log.stats.problems.size(), 1u);
    EXPECT_NE(log.stats.problems[0].message.find("zero-filled tail (4096 bytes of zeros"), std::string::npos)
        << log.stats.problems[0].message;
  }
}

std::string header_error(const fs::path& path) {
  try {
    read_sample_log(path);
  } catch (const SampleLogError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SampleLog, BadHeadersAreClearErrors) {
  ScratchDir dir;
  const std::vector<unsigned char> good = write_log(dir / "good.pflog", make_samples(3));
  const fs::path p = dir / "bad.pflog";
  const std::string name = p.string();

  std::vector<unsigned char> b = good;
  b[0] = 'X';
  spit(p, b);
  EXPECT_EQ(header_error(p), name + ": offset 0: not a posefair sample log (bad magic: expected "
                                    "50 46 4c 4f 47 00 00 01, found 58 46 4c 4f 47 00 00 01)");

  spit(p, std::vector<unsigned char>{'#', ' ', 't', 'i', 'm', 'e'});  // a text file
  EXPECT_NE(header_error(p).find("not a posefair sample log (bad magic"), std::string::npos);

  b = good;
  b[8] = 2;  // version 2, with a header CRC that matches
  detail::put_u32(b.data() + header_size() - 4, detail::crc32(b.data(), header_size() - 4));
  spit(p, b);
  EXPECT_EQ(header_error(p), name + ": offset 8: unsupported format version 2 (this reader reads version 1)");

  b = good;
  b[20] ^= 1;  // a byte of the first stream's name
  spit(p, b);
  const std::string crc = header_error(p);
  EXPECT_EQ(crc.find(name + ": offset " + std::to_string(header_size() - 4) + ": header CRC mismatch (stored 0x"), 0u)
      << crc;

  b = good;
  detail::put_u16(b.data() + 10, 5);
  spit(p, b);
  EXPECT_EQ(header_error(p), name + ": offset 10: header length 5 is too small (at least 18)");

  // A stream table that claims more than the header holds (consistent CRC).
  b = good;
  detail::put_u16(b.data() + 12, 4);
  detail::put_u32(b.data() + header_size() - 4, detail::crc32(b.data(), header_size() - 4));
  spit(p, b);
  EXPECT_NE(header_error(p).find("malformed stream table (entry 3 of 4 runs past the header's end)"),
            std::string::npos)
      << header_error(p);

  for (std::size_t size = 1; size < header_size(); ++size) {
    spit(p, std::vector<unsigned char>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(size)));
    const std::string e = header_error(p);
    EXPECT_NE(e.find(name + ": offset 0: truncated header ("), std::string::npos) << size << ": " << e;
  }
  spit(p, {});
  EXPECT_EQ(header_error(p), name + ": empty file: no sample log header");
  EXPECT_EQ(header_error(dir / "missing.pflog"), (dir / "missing.pflog").string() + ": cannot open: No such file or directory");
  EXPECT_EQ(header_error(dir.path()), dir.path().string() + ": is a directory, not a sample log");
  EXPECT_THROW(read_sample_log_set(dir / "missing.pflog"), SampleLogError);
}

TEST(SampleLog, ASetWhosePartsDisagreeIsRefused) {
  ScratchDir dir;
  write_log(dir / "run.pflog", make_samples(3));
  SampleLogHeader other;
  other.streams = {{1, "other", ""}};
  {
    SampleLogWriter w(dir / "run.1.pflog", other, quick());
    w.append(make_samples(1)[0]);
  }
  try {
    read_sample_log_set(dir / "run.pflog");
    FAIL() << "no error";
  } catch (const SampleLogError& e) {
    EXPECT_NE(std::string(e.what()).find("header differs"), std::string::npos) << e.what();
  }
}

TEST(SampleLog, TheReaderStreamsRecordByRecord) {
  ScratchDir dir;
  const std::vector<Sample> samples = make_samples(50);
  write_log(dir / "run.pflog", samples);
  SampleLogReader reader(dir / "run.pflog");
  EXPECT_EQ(reader.header(), three_streams());
  Sample s;
  std::size_t n = 0;
  while (reader.next(s)) ASSERT_TRUE(bit_identical(s, samples[n++]));
  EXPECT_EQ(n, 50u);
  EXPECT_FALSE(reader.next(s));
  EXPECT_TRUE(reader.stats().problems.empty());
}

}  // namespace
}  // namespace posefair::formats
