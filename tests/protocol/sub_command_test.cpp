// `posefair sub` end to end: the real binary on 127.0.0.1 against a test sender.
#include <netinet/in.h>
#include <signal.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "posefair/daemon/json_lines.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "sub_scenario.hpp"

namespace posefair::testing {
namespace {

using namespace std::chrono_literals;

const std::string kPosefair = POSEFAIR_CLI_PROGRAM;
constexpr const char* kCsvHeader = "session,stream,seq,t,sent,qw,qx,qy,qz,px,py,pz,wx,wy,wz,flags,latency_us";

std::vector<std::string> sub_args(std::vector<std::string> extra) {
  std::vector<std::string> a = {kPosefair, "sub", "--listen", "127.0.0.1:0", "--duration", "20"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// Runs posefair sub with arguments that make it exit at once (bad options, busy port).
std::pair<std::optional<int>, std::string> run_to_exit(std::vector<std::string> args) {
  TempDir dir;
  // Should an option wrongly be accepted, the run stays on loopback.
  if (std::find(args.begin(), args.end(), "--listen") == args.end()) args.insert(args.begin(), {"--listen", "127.0.0.1:0"});
  args.insert(args.begin(), {kPosefair, "sub"});
  Subprocess p(args, dir / "out", dir / "err");
  const auto rc = p.wait(10s);
  return {rc, p.err()};
}

TEST(SubCommand, CsvEndToEndCountsLossReorderingDuplicatesAndMalformed) {
  TempDir dir;
  const Scenario sc = make_scenario();
  ASSERT_EQ(sc.poses.size(), 202u);
  ASSERT_EQ(sc.datagrams.size(), 212u);
  const SubRun r = run_subscriber(sub_args({"--count", "202", "--format", "csv"}), sc, dir);
  ASSERT_TRUE(r.port) << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const auto lines = split_lines(r.out);
  ASSERT_EQ(lines.size(), 1 + sc.poses.size()) << r.out.substr(0, 2000);
  EXPECT_EQ(lines[0], kCsvHeader);
  for (std::size_t i = 0; i < sc.poses.size(); ++i) {
    const std::string expected = csv_row_without_latency(sc.poses[i]);
    ASSERT_EQ(lines[i + 1].substr(0, expected.size()), expected) << "pose " << i;
    const double latency_us = std::stod(lines[i + 1].substr(expected.size()));
    EXPECT_GE(latency_us, 0.0) << lines[i + 1];
    EXPECT_LT(latency_us, 60e6) << lines[i + 1];
  }
  // The printed numbers round-trip: the first row's time and quaternion, bit for bit.
  EXPECT_NE(lines[1].find(",10,"), std::string::npos) << lines[1];

  const std::string stats = stats_line(r.err);
  const std::string expected_counts = "stats: received 202, lost 5, reordered 3, duplicates 2, malformed 10 (" +
                                      sc.malformed_reasons + ")";
  EXPECT_EQ(stats.substr(0, expected_counts.size()), expected_counts) << r.err;
  EXPECT_TRUE(has_latency_tail(stats)) << stats;
  EXPECT_NE(r.err.find("listening on 127.0.0.1:" + std::to_string(*r.port)), std::string::npos) << r.err;
}

TEST(SubCommand, JsonFormatPrintsTheProtocolsJsonLines) {
  TempDir dir;
  const Scenario sc = make_clean_scenario(24);
  const SubRun r = run_subscriber(sub_args({"--count", "24", "--format", "json"}), sc, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = split_lines(r.out);
  ASSERT_EQ(lines.size(), 24u) << r.out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines[i] + "\n", daemon::encode_json(sc.poses[i])) << i;
    const auto d = daemon::decode_json(lines[i]);
    ASSERT_TRUE(d.ok()) << lines[i];
    EXPECT_TRUE(daemon::bitwise_equal(d.message, sc.poses[i])) << lines[i];
  }
  EXPECT_EQ(stats_line(r.err).rfind("stats: received 24, lost 0, reordered 0, duplicates 0, malformed 0, latency min ", 0),
            0u)
      << r.err;
}

TEST(SubCommand, TextFormatIsOneReadableLinePerPose) {
  TempDir dir;
  const Scenario sc = make_clean_scenario(8);
  const SubRun r = run_subscriber(sub_args({"--count", "8"}), sc, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = split_lines(r.out);
  ASSERT_EQ(lines.size(), 8u) << r.out;
  // session c0ffee02 stream 6 seq N t T q W X Y Z [p X Y Z] [w X Y Z] [clamped] [bridged]
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const PoseMessage& m = sc.poses[i];
    const auto w = split_words(lines[i]);
    ASSERT_GE(w.size(), 13u) << lines[i];
    EXPECT_EQ(w[0] + " " + w[1] + " " + w[2] + " " + w[3] + " " + w[4], "session c0ffee02 stream 6 seq");
    EXPECT_EQ(w[5], std::to_string(i));
    EXPECT_EQ(w[6], "t");
    EXPECT_NEAR(std::stod(w[7]), m.sample_time, 1e-6);
    EXPECT_EQ(w[8], "q");
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(std::stod(w[9 + k]), m.orientation.coeffs()[(k + 3) % 4], 1e-6) << lines[i];
    std::size_t at = 13;
    auto vec = [&](const char* tag, const std::optional<Vec3>& v) {
      if (!v) return;
      ASSERT_LT(at + 3, w.size()) << lines[i];
      EXPECT_EQ(w[at], tag) << lines[i];
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::stod(w[at + 1 + k]), (*v)[k], 1e-6) << lines[i];
      at += 4;
    };
    vec("p", m.position);
    vec("w", m.angular_velocity);
    std::string rest;
    for (; at < w.size(); ++at) rest += " " + w[at];
    EXPECT_EQ(rest, std::string(m.clamped() ? " clamped" : "") + (m.bridged() ? " bridged" : "")) << lines[i];
  }
}

TEST(SubCommand, QuietPrintsOnlyStatisticsAndStatsAddsPerStreamLines) {
  TempDir dir;
  Scenario sc = make_clean_scenario(5, 0xAAAA0001u, 1);
  const Scenario other = make_clean_scenario(5, 0xAAAA0001u, 2);
  sc.datagrams.insert(sc.datagrams.end(), other.datagrams.begin(), other.datagrams.end());
  const SubRun r = run_subscriber(sub_args({"--count", "10", "--quiet", "--stats", "--format", "csv"}), sc, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("stream 1 session aaaa0001: received 5, lost 0, reordered 0, duplicates 0, seq 0..4"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("stream 2 session aaaa0001: received 5,"), std::string::npos) << r.err;
  EXPECT_EQ(stats_line(r.err).rfind("stats: received 10, lost 0,", 0), 0u) << r.err;
}

TEST(SubCommand, DurationEndsARunWithoutTraffic) {
  TempDir dir;
  Subprocess p({kPosefair, "sub", "--listen", "127.0.0.1:0", "--duration", "0.3"}, dir / "out", dir / "err");
  const auto t0 = std::chrono::steady_clock::now();
  const auto rc = p.wait(10s);
  ASSERT_EQ(rc, 0) << p.err();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
  EXPECT_EQ(p.out(), "");
  EXPECT_EQ(stats_line(p.err()), "stats: received 0, lost 0, reordered 0, duplicates 0, malformed 0, latency n/a");
}

TEST(SubCommand, SigintEndsTheRunWithStatistics) {
  TempDir dir;
  Subprocess p({kPosefair, "sub", "--listen", "127.0.0.1:0", "--duration", "20", "--format", "csv"}, dir / "out",
               dir / "err");
  const auto port = p.wait_for_listening_port(10s);
  ASSERT_TRUE(port) << p.err();
  send_scenario(make_clean_scenario(3), *port);
  // Wait until all three are printed (header + 3 rows), then interrupt.
  for (int i = 0; i < 500 && split_lines(p.out()).size() < 4; ++i) std::this_thread::sleep_for(10ms);
  p.send_signal(SIGINT);
  const auto rc = p.wait(10s);
  ASSERT_EQ(rc, 0) << p.err();
  EXPECT_EQ(split_lines(p.out()).size(), 4u);
  EXPECT_EQ(stats_line(p.err()).rfind("stats: received 3, lost 0, reordered 0, duplicates 0, malformed 0", 0), 0u)
      << p.err();
}

TEST(SubCommand, BusyPortExitsUnavailable) {
  // A socket without SO_REUSEADDR holds the port.
  daemon::UdpSocket holder = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"));
  const std::string taken = holder.local_endpoint().to_string();
  const auto [rc, err] = run_to_exit({"--listen", taken, "--duration", "5"});
  EXPECT_EQ(rc, 69) << err;
  EXPECT_NE(err.find("cannot bind UDP " + taken), std::string::npos) << err;
}

TEST(SubCommand, BadOptionsExitUsage) {
  const std::vector<std::vector<std::string>> bad = {
      {"--format", "xml"},
      {"--listen", "not-an-address"},
      {"--listen", "127.0.0.1:99999"},
      {"--group", "10.0.0.1"},           // not multicast
      {"--group", "ff12::1"},            // families differ (--listen 127.0.0.1:0)
      {"--interface", "lo"},             // without --group
      {"--count", "-1"},
      {"--duration", "-1"},
      {"--no-such-option"},
  };
  for (const auto& args : bad) {
    auto full = args;
    full.insert(full.end(), {"--duration", "1"});
    if (args[0] == "--duration") full = args;
    const auto [rc, err] = run_to_exit(full);
    EXPECT_EQ(rc, 64) << args[0] << " " << (args.size() > 1 ? args[1] : "") << ": " << err;
  }
}

}  // namespace
}  // namespace posefair::testing
