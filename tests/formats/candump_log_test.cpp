// candump log files (formats/src/candump_log.cpp): every frame syntax can-utils writes,
// malformed lines with their numbers, and the writer. Their replay through the CAN decoders is
// tested in tests/drivers/decoders/candump_replay_test.cpp.
// The example lines follow can-utils' lib.h, whose comment lists "123#R", "12345678#R5",
// "123#11.22.33.44.55.66.77.88", "32345678#112233" (an error frame) and "123##2112233" (CAN FD,
// ESI) as the forms of its compact format.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../support/hex_bytes.hpp"
#include "../support/random_can_frames.hpp"
#include "posefair/formats/candump_log.hpp"

namespace posefair::formats {
namespace {

using namespace ::posefair::testing;

std::vector<std::uint8_t> payload_of(const CanFrame& f) { return {f.data.begin(), f.data.begin() + f.len}; }

TEST(CandumpLog, EveryFrameSyntax) {
  const CandumpLog log = parse_candump_log(
      "(1436509052.249713) vcan0 044#2A366C2BBA\n"
      "(1436509052.449847) can1 12345678#1122\n"
      "(1436509052.650000) vcan0 123#11.22.33.44.55.66.77.88\n"
      "(1436509052.700000) vcan0 123#R\n"
      "(1436509052.710000) vcan0 12345678#R5\n"
      "(1436509052.720000) vcan0 123#1122334455667788_E\n"
      "(1436509052.730000) vcan0 123##2112233\n"
      "(1436509052.740000) vcan0 32345678#112233\n"
      "(1436509052.750000) vcan0 7ff#\n"
      "\n"
      "(1436509052.760000) vcan0 1aB#ff T\n"
      "(1436509052.770000) vcan0 456##1" + std::string(128, 'A') + "\r\n");
  EXPECT_TRUE(log.problems.empty()) << (log.problems.empty() ? "" : log.problems[0].message);
  ASSERT_EQ(log.records.size(), 11u);
  EXPECT_EQ(log.lines, 12u);
  const auto& r = log.records;
  EXPECT_EQ(r[0].frame.can_id, 0x044u);
  EXPECT_EQ(payload_of(r[0].frame), hex("2A 36 6C 2B BA"));
  EXPECT_DOUBLE_EQ(r[0].frame.timestamp, 1436509052.249713);
  EXPECT_EQ(r[0].interface, "vcan0");
  EXPECT_EQ(r[0].line, 1u);
  EXPECT_EQ(r[1].frame.can_id, 0x12345678u | CanFrame::kEffFlag);
  EXPECT_EQ(r[1].interface, "can1");
  EXPECT_EQ(payload_of(r[2].frame), hex("11 22 33 44 55 66 77 88"));
  EXPECT_TRUE(r[3].frame.remote());
  EXPECT_EQ(r[3].frame.len, 0u);
  EXPECT_TRUE(r[4].frame.remote() && r[4].frame.extended());
  EXPECT_EQ(r[4].frame.len, 5u);
  EXPECT_EQ(r[5].frame.len, 8u);  // raw DLC E, 8 bytes
  EXPECT_TRUE(r[6].frame.fd);
  EXPECT_EQ(r[6].frame.fd_flags, CanFrame::kFdEsi | CanFrame::kFdFdf);
  EXPECT_EQ(payload_of(r[6].frame), hex("11 22 33"));
  EXPECT_TRUE(r[7].frame.error());
  EXPECT_FALSE(r[7].frame.extended());
  EXPECT_EQ(r[7].frame.can_id, 0x32345678u);
  EXPECT_EQ(r[8].frame.len, 0u);
  EXPECT_EQ(r[9].frame.can_id, 0x1ABu);
  EXPECT_EQ(r[9].line, 11u);
  EXPECT_EQ(r[10].frame.len, 64u);
  EXPECT_EQ(r[10].frame.fd_flags, CanFrame::kFdBrs | CanFrame::kFdFdf);
}

TEST(CandumpLog, MalformedLinesAreReportedWithTheirNumbersAndSkipped) {
  const std::vector<std::string> bad = {
      "vcan0 123#11",                         // no time
      "(123) vcan0 123#11",                   // time without fraction
      "(12a.5) vcan0 123#11",                 // bad time
      "(1.5) vcan0",                          // no frame
      "(1.5) vcan0 12#11",                    // 2-digit id
      "(1.5) vcan0 800#11",                   // standard id above 7FF
      "(1.5) vcan0 9FFFFFFF#11",              // extended id above 1FFFFFFF (no ERR bit)
      "(1.5) vcan0 123#1",                    // half a byte
      "(1.5) vcan0 123#112233445566778899",   // 9 classic bytes
      "(1.5) vcan0 123#11_E",                 // raw DLC after fewer than 8 bytes
      "(1.5) vcan0 123##0112233445566778899", // FD length 9
      "(1.5) vcan0 123##9",                   // FD flags digit 9
      "(1.5) vcan0 123#R9",                   // remote length 9
      "(1.5) vcan0 123#11 X",                 // trailing junk
      "(1.5) vcan0 123 11",                   // no '#'
      "(1.5) vcan0 123#..11",                 // separators
  };
  std::string text = "(1.000000) vcan0 100#01\n";
  for (const auto& b : bad) text += b + "\n";
  text += "(2.000000) vcan0 100#02\n";
  const CandumpLog log = parse_candump_log(text);
  ASSERT_EQ(log.records.size(), 2u);
  EXPECT_EQ(log.records[1].line, bad.size() + 2);
  ASSERT_EQ(log.problems.size(), bad.size());
  for (std::size_t k = 0; k < bad.size(); ++k) {
    EXPECT_EQ(log.problems[k].line, k + 2) << bad[k];
    EXPECT_FALSE(log.problems[k].message.empty());
  }
}

TEST(CandumpLog, WriterAndParserAgree) {
  std::mt19937_64 rng(31);
  std::vector<CanFrame> frames = random_frames(500, {0x123, 0x7FF, 0x1ABCDEF0 | CanFrame::kEffFlag}, rng);
  frames[3].can_id |= CanFrame::kRtrFlag;
  frames[4].can_id = CanFrame::kErrFlag | 0x10;
  frames[5].fd = true;
  frames[5].fd_flags = CanFrame::kFdBrs | CanFrame::kFdFdf;
  frames[5].len = 48;
  std::string text;
  for (auto& f : frames) {
    f.timestamp = 1700000000.0 + std::round(f.timestamp * 1e6) / 1e6;
    text += format_candump_line(f, "can0") + "\n";
  }
  EXPECT_EQ(format_candump_line(CanFrame::make(0x44, false, hex("2A 36"), 1.5), "vcan0"), "(1.500000) vcan0 044#2A36");
  const CandumpLog log = parse_candump_log(text);
  ASSERT_TRUE(log.problems.empty()) << log.problems[0].message;
  ASSERT_EQ(log.records.size(), frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const CanFrame& a = frames[k];
    const CanFrame& b = log.records[k].frame;
    EXPECT_EQ(a.can_id, b.can_id) << k;
    EXPECT_EQ(a.len, b.len) << k;
    EXPECT_EQ(a.fd, b.fd) << k;
    if (!a.remote()) {
      EXPECT_TRUE(std::equal(a.data.begin(), a.data.begin() + a.len, b.data.begin())) << k;
    }
    EXPECT_NEAR(a.timestamp, b.timestamp, 1e-6) << k;
  }
}

TEST(CandumpLog, UnreadableFileThrows) {
  EXPECT_THROW(read_candump_log("/nonexistent/posefair/bus.log"), CandumpFileError);
}

}  // namespace
}  // namespace posefair::formats
