// A recorded CAN bus replayed through the real posefaird: a candump log written here with the
// decoders' frame encoders (posefair-can and DroneCAN ahrs.Solution on can0, Xsens MTi CAN on
// can1, a few malformed lines among them), three streams reading it with type = "replay" and
// key candump, every pose collected over UDP on 127.0.0.1.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "../support/daemon_process.hpp"
#include "../support/test_files.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"
#include "posefair/formats/candump_log.hpp"

namespace posefair::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int kSamples = 150;  // per stream, 100 Hz

// A slow rotation, different per stream, so a mixed-up stream shows.
Quat orientation(int stream, int k) {
  const Vec3 axis = stream == 1 ? Vec3(0, 0, 1) : stream == 2 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  return Quat(Eigen::AngleAxisd(0.3 * stream + 0.01 * k, axis));
}

std::string candump_log() {
  std::string log;
  auto add = [&](const std::vector<drivers::CanFrame>& frames, const char* interface) {
    for (const drivers::CanFrame& f : frames) log += formats::format_candump_line(f, interface) + "\n";
  };
  const std::vector<std::uint8_t> no_bytes;
  for (int k = 0; k < kSamples; ++k) {
    const double t = 1700000000.0 + 0.01 * k;
    add(drivers::encode_posefair_can(0x204, false, orientation(1, k), 5000000u + 10000u * static_cast<std::uint32_t>(k),
                                     nullptr, static_cast<std::uint8_t>(k), t),
        "can0");
    add(drivers::encode_xsens_can(orientation(2, k), 100u * static_cast<std::uint32_t>(k),
                                  static_cast<std::uint16_t>(k), t + 0.001),
        "can1");
    const std::vector<std::uint8_t> payload =
        drivers::serialize_dronecan_ahrs_solution(orientation(3, k), 2000000u + 10000u * static_cast<std::uint64_t>(k));
    add(drivers::encode_dronecan_transfer(drivers::kDroneCanAhrsSolutionId, drivers::kDroneCanAhrsSolutionSignature,
                                          payload, 42, static_cast<std::uint8_t>(k & 31), 16, t + 0.002),
        "can0");
    if (k == 10) log += "this is not a candump line\n";
    if (k == 20) log += "(1700000000.205000) can0 12G#00\n";
  }
  return log;
}

TEST(DaemonCandump, ThreeProtocolsFromOneLogArePublishedWithTheirOrientations) {
  ScratchDir dir("posefair-can-e2e-");
  Collector poses;
  write_text(dir / "bus.log", candump_log());
  const fs::path config = dir / "posefaird.toml";
  write_text(config,
             "[daemon]\nexit_when_sources_end = true\n[logging]\nstatus_interval = 0\n"
             "[engine]\nepsilon_r = 0.02\n\n"
             "[[stream]]\nid = 1\nname = \"glove\"\n"
             "driver = { type = \"replay\", candump = \"bus.log\", interface = \"can0\", protocol = \"posefair-can\", "
             "posefair_base_id = 0x204, timing = \"fast\" }\n\n"
             "[[stream]]\nid = 2\nname = \"mti\"\n"
             "driver = { type = \"replay\", candump = \"bus.log\", interface = \"can1\", protocol = \"xsens-can\", "
             "timing = \"fast\" }\n\n"
             "[[stream]]\nid = 3\nname = \"ahrs\"\n"
             "driver = { type = \"replay\", candump = \"bus.log\", interface = \"can0\", protocol = \"dronecan-ahrs\", "
             "dronecan_node_id = \"42\", timing = \"fast\" }\n\n"
             "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(poses.port()) + "\"]\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_EQ(d.wait(60s), 0) << d.err();
  ASSERT_TRUE(wait_until([&] { return poses.count(1) + poses.count(2) + poses.count(3) >= 3u * kSamples; }, 5s))
      << poses.count(1) << " " << poses.count(2) << " " << poses.count(3) << "\n" << d.err();

  // The malformed lines are reported by line number (each stream's replay reads the log).
  EXPECT_EQ(count_of(d.err(), "candump " + (dir / "bus.log").string() + ": line "), 6u) << d.err();

  std::vector<int> seen(4, 0);
  for (const Collector::Got& g : poses.all()) {
    const std::uint32_t s = g.m.stream;
    ASSERT_GE(s, 1u);
    ASSERT_LE(s, 3u);
    const int k = static_cast<int>(g.m.sequence);
    ASSERT_LT(k, kSamples);
    ++seen[s];
    // epsilon_r bounds the faired pose against its measurement; the measurement is the sent
    // orientation within int16 (posefair-can, Xsens) or float16 (DroneCAN) rounding.
    EXPECT_LE(so3::rotation_angle(g.m.orientation, orientation(static_cast<int>(s), k)), 0.02 + 2e-3)
        << "stream " << s << " pose " << k;
  }
  EXPECT_EQ(seen[1], kSamples);
  EXPECT_EQ(seen[2], kSamples);
  EXPECT_EQ(seen[3], kSamples);
}

TEST(DaemonCandump, ALogWithoutFramesOfTheProtocolIsRefusedAtStart) {
  ScratchDir dir("posefair-can-e2e-");
  write_text(dir / "bus.log", candump_log());
  const fs::path config = dir / "posefaird.toml";
  write_text(config,
             "[[stream]]\nid = 1\nname = \"mti\"\n"
             "driver = { type = \"replay\", candump = \"bus.log\", interface = \"can0\", protocol = \"xsens-can\" }\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  const auto rc = d.wait(30s);
  ASSERT_TRUE(rc.has_value()) << d.err();
  EXPECT_NE(*rc, 0);
  EXPECT_NE(d.err().find("no samples decoded"), std::string::npos) << d.err();
}

}  // namespace
}  // namespace posefair::testing
