// The OSC encodings (vmc, vrchat) received by a program posefair did not write: oscdump, from
// Debian's liblo-tools, listening on a port of 127.0.0.1's host; the test sends each encoder's
// datagram there and reads the values oscdump prints. Known rotations go in (a turn to the
// left, a pitch up) and must come out as Unity and VRChat show them.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "known_rotations.hpp"
#include "subprocess.hpp"

namespace posefair::testing {
namespace {

using namespace std::chrono_literals;
using daemon::Endpoint;
using daemon::OutputStream;
using daemon::PoseMessage;

// A UDP port free on this host now (bound to port 0, read, released) for oscdump to take.
std::uint16_t free_udp_port() {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  close(fd);
  return ntohs(a.sin_port);
}

// One oscdump message line split into words: path, type tags, arguments (strings unquoted).
struct OscLine {
  std::string path, types;
  std::vector<std::string> args;
  double number(std::size_t i) const { return std::stod(args.at(i)); }
};

// Runs oscdump, sends `datagram` to it every 50 ms until it has printed `lines` messages (it
// needs a moment to bind), and returns what it printed: one line per message, a bundle's
// messages each on its own line after the bundle's timetag.
std::vector<OscLine> through_oscdump(const std::vector<std::uint8_t>& datagram, std::size_t lines) {
  TempDir dir;
  const std::uint16_t port = free_udp_port();
  Subprocess dump({"/usr/bin/oscdump", "-L", std::to_string(port)}, dir / "out", dir / "err");
  daemon::UdpSender sender({*Endpoint::parse("127.0.0.1:" + std::to_string(port))});
  std::vector<OscLine> parsed;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < deadline) {
    sender.send(datagram);
    std::this_thread::sleep_for(50ms);
    std::istringstream out(dump.out());
    parsed.clear();
    for (std::string line; std::getline(out, line);) {
      std::istringstream words(line);
      std::vector<std::string> w;
      for (std::string s; words >> s;) w.push_back(s);
      // "<timetag> /path types args..." for a bundle's message, "/path types args..." otherwise.
      std::size_t at = 0;
      while (at < w.size() && w[at].front() != '/') ++at;
      if (at + 1 >= w.size()) continue;
      OscLine l{w[at], w[at + 1], {}};
      for (std::size_t k = at + 2; k < w.size(); ++k) {
        std::string a = w[k];
        if (a.size() >= 2 && a.front() == '"' && a.back() == '"') a = a.substr(1, a.size() - 2);
        l.args.push_back(a);
      }
      parsed.push_back(l);
    }
    if (parsed.size() >= lines) break;
  }
  dump.send_signal(SIGTERM);
  (void)dump.wait(5s);
  EXPECT_GE(parsed.size(), lines) << "oscdump printed: " << dump.out() << dump.err();
  parsed.resize(std::min(parsed.size(), lines));
  return parsed;
}

std::vector<std::uint8_t> encode(std::string_view encoding, const posefair::OptionMap& options,
                                 std::vector<OutputStream> streams, const PoseMessage& m) {
  const auto encoder = daemon::find_output_encoder(encoding)->make(options, streams);
  std::vector<std::uint8_t> buffer(daemon::kMaxDatagramSize);
  buffer.resize(encoder->encode(m, buffer));
  return buffer;
}

TEST(OscThroughOscdump, VmcRootIsAUnityPoseWithOkAndTime) {
  // 1 m forward, 0.5 m left, 1.5 m up, turned 90° left: Unity (x right, y up, z forward)
  // position (-0.5, 1.5, 1); rotation -90° about Unity's y: (0, -sin 45°, 0, cos 45°).
  const auto lines = through_oscdump(encode("vmc", {}, {{3, "body"}}, pose(turn_left(90), Vec3(1.0, 0.5, 1.5), 3, 2.5)), 3);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].path, "/VMC/Ext/Root/Pos");
  EXPECT_EQ(lines[0].types, "sfffffff");
  ASSERT_EQ(lines[0].args.size(), 8u);
  EXPECT_EQ(lines[0].args[0], "root");
  const double expected[] = {-0.5, 1.5, 1.0, 0.0, -std::sqrt(0.5), 0.0, std::sqrt(0.5)};
  for (std::size_t i = 0; i < 7; ++i) EXPECT_NEAR(lines[0].number(i + 1), expected[i], 1e-6) << "argument " << i + 1;
  EXPECT_EQ(lines[1].path, "/VMC/Ext/OK");
  EXPECT_EQ(lines[1].types, "i");
  EXPECT_EQ(lines[1].args, std::vector<std::string>{"1"});
  EXPECT_EQ(lines[2].path, "/VMC/Ext/T");
  EXPECT_EQ(lines[2].types, "f");
  EXPECT_NEAR(lines[2].number(0), 2.5, 1e-6);
}

TEST(OscThroughOscdump, VmcBonePitchedUpIsANegativeUnityXRotation) {
  const auto lines = through_oscdump(
      encode("vmc", {{"bones", std::vector<std::string>{"Hips", "Head"}}}, {{1, "hips"}, {2, "head"}}, pose(pitch_up(30), std::nullopt, 2)), 1);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].path, "/VMC/Ext/Bone/Pos");
  ASSERT_EQ(lines[0].args.size(), 8u);
  EXPECT_EQ(lines[0].args[0], "Head");
  const double expected[] = {0.0, 0.0, 0.0, -std::sin(15 * kDeg), 0.0, 0.0, std::cos(15 * kDeg)};
  for (std::size_t i = 0; i < 7; ++i) EXPECT_NEAR(lines[0].number(i + 1), expected[i], 1e-6) << "argument " << i + 1;
}

TEST(OscThroughOscdump, VrchatTrackerTurnedLeftIsMinus90AboutY) {
  const auto lines = through_oscdump(encode("vrchat", {{"trackers", std::vector<std::string>{"head", "3"}}},
                                            {{1, "head"}, {2, "hip"}}, pose(turn_left(90), Vec3(0.0, 0.0, 1.7), 1)),
                                     2);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].path, "/tracking/trackers/head/position");
  EXPECT_EQ(lines[0].types, "fff");
  ASSERT_EQ(lines[0].args.size(), 3u);
  EXPECT_NEAR(lines[0].number(0), 0.0, 1e-6);
  EXPECT_NEAR(lines[0].number(1), 1.7, 1e-6);
  EXPECT_NEAR(lines[0].number(2), 0.0, 1e-6);
  EXPECT_EQ(lines[1].path, "/tracking/trackers/head/rotation");
  ASSERT_EQ(lines[1].args.size(), 3u);
  EXPECT_NEAR(lines[1].number(0), 0.0, 1e-4);
  EXPECT_NEAR(lines[1].number(1), -90.0, 1e-4);
  EXPECT_NEAR(lines[1].number(2), 0.0, 1e-4);
}

TEST(OscThroughOscdump, VrchatTrackerPitchedUpWithoutPositionSendsOnlyItsRotation) {
  const auto lines = through_oscdump(encode("vrchat", {{"trackers", std::vector<std::string>{"head", "3"}}},
                                            {{1, "head"}, {2, "hip"}}, pose(pitch_up(30), std::nullopt, 2)),
                                     1);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].path, "/tracking/trackers/3/rotation");
  EXPECT_EQ(lines[0].types, "fff");
  ASSERT_EQ(lines[0].args.size(), 3u);
  EXPECT_NEAR(lines[0].number(0), -30.0, 1e-4);
  EXPECT_NEAR(lines[0].number(1), 0.0, 1e-4);
  EXPECT_NEAR(lines[0].number(2), 0.0, 1e-4);
}

}  // namespace
}  // namespace posefair::testing
