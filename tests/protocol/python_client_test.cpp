// tools/posefair_sub.py, the standard-library Python client: end to end on 127.0.0.1 against
// the same sender as `posefair sub`, and its decoder against the C++ one on a fuzzed corpus.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "posefair/daemon/json_lines.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "sub_scenario.hpp"

namespace posefair::testing {
namespace {

using namespace std::chrono_literals;

const std::string kPython = "/usr/bin/python3";
const std::string kClient = POSEFAIR_SOURCE_DIR "/tools/posefair_sub.py";

std::vector<std::string> client_args(std::vector<std::string> extra) {
  std::vector<std::string> a = {kPython, kClient, "--listen", "127.0.0.1:0", "--duration", "20"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

TEST(PythonClient, CsvEndToEndMatchesPosefairSub) {
  TempDir dir;
  const Scenario sc = make_scenario();
  const SubRun r = run_subscriber(client_args({"--count", "202", "--format", "csv"}), sc, dir);
  ASSERT_TRUE(r.port) << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = split_lines(r.out);
  ASSERT_EQ(lines.size(), 1 + sc.poses.size()) << r.out.substr(0, 2000) << r.err;
  EXPECT_EQ(lines[0], "session,stream,seq,t,sent,qw,qx,qy,qz,px,py,pz,wx,wy,wz,flags,latency_us");
  for (std::size_t i = 0; i < sc.poses.size(); ++i) {
    const std::string expected = csv_row_without_latency(sc.poses[i]);
    ASSERT_EQ(lines[i + 1].substr(0, expected.size()), expected) << "pose " << i;
    const double latency_us = std::stod(lines[i + 1].substr(expected.size()));
    EXPECT_GE(latency_us, 0.0) << lines[i + 1];
    EXPECT_LT(latency_us, 60e6) << lines[i + 1];
  }
  const std::string stats = stats_line(r.err);
  const std::string expected_counts = "stats: received 202, lost 5, reordered 3, duplicates 2, malformed 10 (" +
                                      sc.malformed_reasons + ")";
  EXPECT_EQ(stats.substr(0, expected_counts.size()), expected_counts) << r.err;
  EXPECT_TRUE(has_latency_tail(stats)) << stats;
}

TEST(PythonClient, JsonOutputIsByteForByteTheProtocolsJsonLines) {
  TempDir dir;
  const Scenario sc = make_clean_scenario(30);
  const SubRun r = run_subscriber(client_args({"--count", "30", "--format", "json", "--stats"}), sc, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = split_lines(r.out);
  ASSERT_EQ(lines.size(), 30u) << r.out << r.err;
  for (std::size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(lines[i] + "\n", daemon::encode_json(sc.poses[i])) << i;
  EXPECT_NE(r.err.find("stream 6 session c0ffee02: received 30, lost 0, reordered 0, duplicates 0, seq 0..29"),
            std::string::npos)
      << r.err;
}

TEST(PythonClient, TextOutputMatchesPosefairSub) {
  TempDir dir;
  const Scenario sc = make_clean_scenario(6);
  const SubRun py = run_subscriber(client_args({"--count", "6"}), sc, dir);
  ASSERT_EQ(py.exit_code, 0) << py.err;
  TempDir dir2;
  const SubRun cpp = run_subscriber(
      {POSEFAIR_CLI_PROGRAM, "sub", "--listen", "127.0.0.1:0", "--duration", "20", "--count", "6"}, sc,
      dir2);
  ASSERT_EQ(cpp.exit_code, 0) << cpp.err;
  EXPECT_EQ(split_lines(py.out).size(), 6u);
  EXPECT_EQ(py.out, cpp.out);
}

TEST(PythonClient, ExitCodesForBadOptionsAndBusyPort) {
  auto run = [](std::vector<std::string> args) {
    TempDir dir;
    // Should an option wrongly be accepted, the run stays on loopback.
    if (std::find(args.begin(), args.end(), "--listen") == args.end()) args.insert(args.begin(), {"--listen", "127.0.0.1:0"});
    args.insert(args.begin(), {kPython, kClient});
    Subprocess p(args, dir / "out", dir / "err");
    const auto rc = p.wait(20s);
    return std::make_pair(rc, p.err());
  };
  for (const auto& bad : std::vector<std::vector<std::string>>{{"--format", "xml", "--duration", "1"},
                                                                {"--listen", "nowhere", "--duration", "1"},
                                                                {"--group", "10.0.0.1", "--duration", "1"},
                                                                {"--group", "ff12::1", "--duration", "1"},
                                                                {"--interface", "lo", "--duration", "1"},
                                                                {"--count", "-1", "--duration", "1"}}) {
    const auto [rc, err] = run(bad);
    EXPECT_EQ(rc, 64) << bad[0] << ": " << err;
  }
  daemon::UdpSocket holder = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"));
  const std::string taken = holder.local_endpoint().to_string();
  const auto [rc, err] = run({"--listen", taken, "--duration", "5"});
  EXPECT_EQ(rc, 69) << err;
  EXPECT_NE(err.find("cannot bind UDP " + taken), std::string::npos) << err;
}

// The two decoders follow one specification: on valid, mutated and random datagrams they
// agree on the verdict (the same reason for every rejection) and on the decoded pose.
TEST(PythonClient, DecoderAgreesWithTheCppDecoderOnAFuzzedCorpus) {
  TempDir dir;
  std::mt19937_64 rng(99);
  std::vector<Bytes> corpus;
  for (const auto& d : make_scenario().datagrams) corpus.push_back(d);
  const auto seeds = corpus;
  for (int i = 0; i < 3000; ++i) {
    Bytes d = seeds[rng() % seeds.size()];
    for (int k = 1 + static_cast<int>(rng() % 3); k > 0; --k) {
      switch (rng() % 4) {
        case 0:
          if (!d.empty()) d[rng() % d.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
          break;
        case 1:
          if (!d.empty()) d[rng() % d.size()] = static_cast<std::uint8_t>("{}[],:\"0-e.\\ n1"[rng() % 15]);
          break;
        case 2:
          d.resize(rng() % (d.size() + 1));
          break;
        case 3:
          if (!d.empty()) d.erase(d.begin() + static_cast<std::ptrdiff_t>(rng() % d.size()));
          break;
      }
    }
    corpus.push_back(d);
  }
  {
    std::ofstream f(dir / "corpus.hex");
    for (const Bytes& d : corpus) {
      for (std::uint8_t b : d) {
        char hex[3];
        std::snprintf(hex, sizeof hex, "%02x", b);
        f << hex;
      }
      f << "\n";
    }
  }
  {
    std::ofstream f(dir / "check.py");
    f << "import sys\n"
         "sys.path.insert(0, sys.argv[1])\n"
         "import posefair_sub as p\n"
         "for line in open(sys.argv[2]):\n"
         "    data = bytes.fromhex(line.strip())\n"
         "    try:\n"
         "        sys.stdout.write('ok ' + p.encode_json(p.decode(data)))\n"
         "    except p.DecodeError as e:\n"
         "        sys.stdout.write(e.reason + '\\n')\n";
  }
  Subprocess py({kPython, (dir / "check.py").string(), POSEFAIR_SOURCE_DIR "/tools", (dir / "corpus.hex").string()},
                dir / "out", dir / "err");
  ASSERT_EQ(py.wait(60s), 0) << py.err();
  const auto verdicts = split_lines(py.out());
  ASSERT_EQ(verdicts.size(), corpus.size()) << py.err();
  std::size_t accepted = 0, rejected = 0;
  for (std::size_t i = 0; i < corpus.size(); ++i) {
    const auto r = daemon::decode_datagram(corpus[i]);
    const std::string expected =
        r.ok() ? "ok " + daemon::encode_json(r.message).substr(0, daemon::encode_json(r.message).size() - 1)
               : std::string(daemon::to_string(r.error));
    EXPECT_EQ(verdicts[i], expected) << "datagram " << i << ": " << std::string(corpus[i].begin(), corpus[i].end());
    (r.ok() ? accepted : rejected)++;
  }
  EXPECT_GT(accepted, 300u);
  EXPECT_GT(rejected, 1000u);
}

}  // namespace
}  // namespace posefair::testing
