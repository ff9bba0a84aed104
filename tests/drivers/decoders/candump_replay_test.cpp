// candump log files replayed through the CAN decoders (drivers/src/candump_replay.cpp): a
// recorded bus decoded and played by the replay driver. The log format itself is tested in
// tests/formats/candump_log_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stop_token>

#include "../../support/can_decoder_testing.hpp"
#include "posefair/drivers/candump_replay.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"
#include "posefair/drivers/replay_driver.hpp"
#include "posefair/formats/candump_log.hpp"

namespace posefair::drivers::candump_replay_test {
namespace {

using namespace ::posefair::testing;
using formats::format_candump_line;
using formats::parse_candump_log;

// A bus recorded as a candump log: a posefair-can tracker at 0x200 among other traffic on two
// interfaces, with a damaged line. Replayed, it gives what the decoder gives fed the frames.
TEST(CandumpReplay, ARecordedBusDecodesAndPlays) {
  std::mt19937_64 rng(41);
  std::vector<CanFrame> tracker;
  std::string text;
  for (int k = 0; k < 200; ++k) {
    const double t = 1700000000.0 + 0.01 * k;
    const Vec3 p(0.001 * k, 0, 0);
    for (const CanFrame& f : encode_posefair_can(0x200, false, random_unit_quaternion(rng), 10000u * static_cast<std::uint32_t>(k), &p,
                                                 static_cast<std::uint8_t>(k), t)) {
      CanFrame g = f;
      g.timestamp = std::round(t * 1e6) / 1e6;
      tracker.push_back(g);
      text += format_candump_line(g, "can0") + "\n";
    }
    text += format_candump_line(CanFrame::make(0x202, false, hex("FF 7F 00 00 00 00 00 00"), t), "can1") + "\n";  // same id, other bus
    text += format_candump_line(CanFrame::make(0x0F0, false, hex("01 02"), t), "can0") + "\n";
    if (k == 100) text += "(garbage\n";
  }
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "posefair_candump_replay_test.log";
  {
    std::ofstream out(path);
    out << text;
  }
  CandumpReplayOptions o;
  o.protocol = "posefair-can";
  o.interface = "can0";
  o.stream_id = 9;
  const CandumpReplay r = decode_candump_file(path, o);
  std::filesystem::remove(path);
  ASSERT_EQ(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].line, 101u * 5 + 1);
  EXPECT_EQ(r.other_interfaces, 200u);
  EXPECT_EQ(r.frame_counters.foreign, 200u);
  const CanDecoded direct = decode_frames(make_posefair_can_decoder(), tracker);
  EXPECT_EQ(r.counters, direct.counters);
  ASSERT_EQ(r.samples.size(), direct.samples.size());
  ASSERT_EQ(r.samples.size(), 200u);
  for (std::size_t k = 0; k < r.samples.size(); ++k) {
    const Sample& s = r.samples[k];
    EXPECT_EQ(s.stream_id, 9u);
    EXPECT_EQ(s.sequence, k);
    EXPECT_EQ(s.orientation.coeffs(), direct.samples[k].orientation.coeffs());
    EXPECT_EQ(s.position, direct.samples[k].position);
    EXPECT_DOUBLE_EQ(s.receive_time, tracker[3 * k + 2].timestamp);
    EXPECT_EQ(s.flags, std::uint32_t{kHasDeviceTime | kHasPosition});
    if (k > 0) {
      EXPECT_GT(s.time, r.samples[k - 1].time);
    }
  }
  // The samples play through the replay driver's in-memory constructor.
  struct Sink final : SampleSink {
    std::vector<Sample> got;
    bool push(const Sample& s) override {
      got.push_back(s);
      return true;
    }
  } sink;
  ReplayOptions ro;
  ro.timing = ReplayTiming::AsFastAsPossible;
  ReplayDriver driver(r.samples, ro, "candump:bus.log");
  driver.run(std::stop_token{}, sink);
  ASSERT_EQ(sink.got.size(), r.samples.size());
  EXPECT_EQ(sink.got[17].orientation.coeffs(), r.samples[17].orientation.coeffs());

  o.protocol = "no-such-bus";
  EXPECT_THROW(decode_candump(parse_candump_log(""), o), std::invalid_argument);
}

}  // namespace
}  // namespace posefair::drivers::candump_replay_test
