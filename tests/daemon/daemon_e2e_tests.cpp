// posefaird end to end: the real binaries (build/daemon/posefaird, build/tools/posefair) as
// child processes, UDP on 127.0.0.1 only. Every wait has a deadline and every child still
// running at the end of a test is killed (Subprocess). Ports are free ones the kernel chose
// (a socket bound to port 0, by the test or by `posefair sub --listen 127.0.0.1:0`).
//
//   FairVsDaemon.*            `posefair fair --causal` and posefaird give the same poses, bit for bit
//   DaemonSignals.Sighup*     a bad config is refused and the running one kept; a good one is
//                             taken with the session and the sequence numbers continued
//   DaemonRecording.*         SIGTERM while recording, the recording replayed; a truncated one
//   DaemonConfigErrors.*      malformed configs exit 78 with FILE:LINE: and the key
//   SubIdle.*                 `posefair sub --idle`
//   DaemonClientEncodings.*   opentrack, freed, vmc and vrchat outputs beside a binary one, with
//                             a stream's mounting and an output's max_rate_hz (dds: tests/dds)
#include <signal.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <map>
#include <vector>

#include "../protocol/subprocess.hpp"
#include "../replay/replay_log.hpp"
#include "../support/daemon_process.hpp"
#include "../support/raw_udp_collector.hpp"
#include "../support/pseudo_terminal.hpp"
#include "../support/test_files.hpp"
#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"
#include "posefair/formats/pose_file.hpp"
#include "posefair/formats/sample_log.hpp"

namespace posefair::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const fs::path kDemoCsv = fs::path(POSEFAIR_SOURCE_DIR) / "data/demo/broad-07-excerpt.csv";
constexpr std::size_t kDemoSamples = 2000;
constexpr int kExitConfig = 78;

// ---------------------------------------------------------------------------------------------
// 1. `posefair fair --causal` and posefaird agree bit for bit

// A CSV table: header names and rows of fields (no quoting: neither file needs it).
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) throw std::runtime_error("no column " + name);
    return static_cast<std::size_t>(it - header.begin());
  }
};

Table read_table(const std::string& text) {
  Table t;
  const auto lines = lines_of(text);
  if (lines.empty()) return t;
  t.header = split(lines[0], ',');
  for (std::size_t i = 1; i < lines.size(); ++i) {
    auto fields = split(lines[i], ',');
    if (!lines[i].empty() && lines[i].back() == ',') fields.push_back("");  // getline drops a trailing empty field
    t.rows.push_back(std::move(fields));
  }
  return t;
}

struct EngineCase {
  const char* name;
  std::vector<std::string> fair_args;  // after --causal
  std::string toml;                    // the same settings as [stream.engine] keys
};

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void run_fair_vs_daemon(const EngineCase& c) {
  ScratchDir dir("posefair-e2e-");
  const fs::path fair_csv = dir / "fair.csv";

  // posefair fair --causal over the demo recording.
  std::vector<std::string> fair = {kPosefair, "fair", kDemoCsv.string(), "-o", fair_csv.string(), "--causal"};
  fair.insert(fair.end(), c.fair_args.begin(), c.fair_args.end());
  Subprocess f(fair, dir / "fair.out", dir / "fair.err");
  ASSERT_EQ(f.wait(60s), 0) << f.out() << f.err();
  // Read back as the daemon's replay driver reads a pose file: a value the fair tool left
  // unchanged keeps the file's text, which stands for the (renormalised) value read, and
  // everything else is written as the shortest text of its double, so this is exact.
  const formats::PoseFile expected_file = formats::read_pose_file(fair_csv, {});
  const PoseSequence& expected = expected_file.poses();
  ASSERT_EQ(expected.size(), kDemoSamples) << f.out();
  ASSERT_TRUE(expected.has_position());
  // The input as the daemon reads it: a pose equal to its measurement is no evidence of fairing.
  const PoseSequence input = formats::read_pose_file(kDemoCsv, {}).poses();
  ASSERT_EQ(input.size(), kDemoSamples);

  // posefair sub on a free port, then posefaird replaying the same file with the same engine.
  Subprocess sub({kPosefair, "sub", "--listen", "127.0.0.1:0", "--format", "csv", "--idle", "2", "--duration", "60"},
                 dir / "sub.out", dir / "sub.err");
  const auto port = sub.wait_for_listening_port(20s);
  ASSERT_TRUE(port) << sub.err();

  const fs::path config = dir / "posefaird.toml";
  write_text(config, std::string("[daemon]\nexit_when_sources_end = true\nsession_id = 3054\n\n") +
                         "[logging]\nstatus_interval = 0\n\n"
                         "[[stream]]\nid = 1\nname = \"broad07\"\nring_capacity = 4096\n"
                         "[stream.driver]\ntype = \"replay\"\npath = \"" +
                         kDemoCsv.string() +
                         "\"\ntiming = \"original\"\nspeed = 10.0\n"
                         "[stream.engine]\n" +
                         c.toml + "\n[[output]]\nencoding = \"binary\"\ndestinations = [\"127.0.0.1:" +
                         std::to_string(*port) + "\"]\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  const auto drc = d.wait(60s);
  ASSERT_EQ(drc, 0) << d.err();
  EXPECT_NE(d.err().find("every source has ended"), std::string::npos) << d.err();
  const auto counters = last_counters(d.err(), "broad07", 1);
  ASSERT_TRUE(counters) << d.err();
  EXPECT_EQ(counters->received, kDemoSamples) << counters->line;
  EXPECT_EQ(counters->dropped, 0u) << counters->line;
  EXPECT_EQ(counters->emitted, kDemoSamples) << counters->line;
  EXPECT_EQ(counters->published, kDemoSamples) << counters->line;
  EXPECT_EQ(counters->send_failures, 0u) << counters->line;

  // sub exits by itself 2 s after the last pose.
  ASSERT_EQ(sub.wait(30s), 0) << sub.err();
  const Table got = read_table(sub.out());
  ASSERT_EQ(got.header.size(), 17u) << sub.out().substr(0, 200);
  EXPECT_NE(sub.err().find("stats: received 2000, lost 0, reordered 0, duplicates 0, malformed 0"), std::string::npos)
      << sub.err();
  ASSERT_EQ(got.rows.size(), kDemoSamples) << sub.err();
  const std::size_t gq[4] = {got.column("qw"), got.column("qx"), got.column("qy"), got.column("qz")};
  const std::size_t gp[3] = {got.column("px"), got.column("py"), got.column("pz")};

  std::size_t value_mismatches = 0, sign_flips = 0, reported = 0, faired = 0;
  for (std::size_t i = 0; i < got.rows.size(); ++i) {
    const auto& g = got.rows[i];
    ASSERT_EQ(g.size(), 17u) << "sub row " << i;
    ASSERT_EQ(to_u64(g[got.column("session")]), 3054u);
    ASSERT_EQ(to_u64(g[got.column("stream")]), 1u);
    ASSERT_EQ(to_u64(g[got.column("seq")]), i) << "poses arrive in order, none lost";
    // The same sample: its time, exactly.
    const double te = expected.time[i], tg = to_double(g[got.column("t")]);
    ASSERT_TRUE(te == tg && same_bits(te, tg)) << "pose " << i << ": time " << g[got.column("t")] << " vs " << te;

    const Quat& q = expected.orientation[i];
    const Vec3& p = expected.position[i];
    const double qe[4] = {q.w(), q.x(), q.y(), q.z()}, pe[3] = {p.x(), p.y(), p.z()};
    double qg[4], pg[3];
    for (int k = 0; k < 4; ++k) qg[k] = to_double(g[gq[k]]);
    for (int k = 0; k < 3; ++k) pg[k] = to_double(g[gp[k]]);
    bool equal = true, negated = true, positions_equal = true;
    for (int k = 0; k < 4; ++k) {
      equal = equal && qe[k] == qg[k] && same_bits(qe[k], qg[k]);
      negated = negated && same_bits(-qe[k], qg[k]);
    }
    for (int k = 0; k < 3; ++k) positions_equal = positions_equal && pe[k] == pg[k] && same_bits(pe[k], pg[k]);
    if (input.orientation[i].coeffs() != q.coeffs()) ++faired;
    if (equal && positions_equal) continue;
    if (negated && positions_equal)
      ++sign_flips;
    else
      ++value_mismatches;
    if (reported++ < 5) {
      char text[512];
      std::snprintf(text, sizeof text,
                    "pose %zu%s: daemon q %.17g %.17g %.17g %.17g p %.17g %.17g %.17g, fair q %.17g %.17g %.17g %.17g "
                    "p %.17g %.17g %.17g",
                    i, negated && positions_equal ? " (quaternion sign differs)" : "", qg[0], qg[1], qg[2], qg[3],
                    pg[0], pg[1], pg[2], qe[0], qe[1], qe[2], qe[3], pe[0], pe[1], pe[2]);
      ADD_FAILURE() << text;
    }
  }
  // Most poses are moved by the fairing (else this would only compare the input with itself).
  EXPECT_GT(faired, kDemoSamples / 2);
  EXPECT_EQ(value_mismatches, 0u) << "poses whose values differ from posefair fair --causal";
  EXPECT_EQ(sign_flips, 0u) << "poses equal up to the quaternion's sign only (fair keeps each input sample's sign, "
                               "the daemon sends the engine's hemisphere-continuous output)";
}

TEST(FairVsDaemon, LinearSolverWithLagIsBitIdentical) {
  run_fair_vs_daemon({"linear, order 3, window 32, lag 4",
                      {"--order", "3", "--window", "32", "--lag", "4", "--smoothing", "2000", "--continuity", "0.5",
                       "--eps-r", "0.05", "--eps-t", "0.005", "--quiet"},
                      "order = 3\nwindow = 32\nlag = 4\nsmoothing = 2000.0\ncontinuity = 0.5\n"
                      "epsilon_r = 0.05\nepsilon_t = 0.005\n"});
}

TEST(FairVsDaemon, GaussNewtonWithoutLagIsBitIdentical) {
  run_fair_vs_daemon({"gauss-newton, order 2, window 24, lag 0",
                      {"--order", "2", "--window", "24", "--lag", "0", "--solver", "gauss-newton",
                       "--window-iterations", "2", "--smoothing", "500", "--continuity", "0.25", "--eps-r", "0.05",
                       "--eps-t", "0.005", "--quiet"},
                      "order = 2\nwindow = 24\nlag = 0\nsolver = \"gauss-newton\"\niterations = 2\n"
                      "smoothing = 500.0\ncontinuity = 0.25\nepsilon_r = 0.05\nepsilon_t = 0.005\n"});
}

// ---------------------------------------------------------------------------------------------
// 3. SIGHUP: a bad config is refused, a good one taken (a new session, or the same with a fixed session_id)

std::string synthetic_config(std::uint16_t port, bool second_stream) {
  std::string s =
      "[logging]\nstatus_interval = 0\n\n"
      "[[stream]]\nid = 1\nname = \"one\"\n"
      "driver = { type = \"synthetic\", rate_hz = 200.0, duration = 0.0 }\n";
  if (second_stream)
    s += "\n[[stream]]\nid = 2\nname = \"two\"\n"
         "driver = { type = \"synthetic\", rate_hz = 200.0, duration = 0.0, seed = 2 }\n";
  s += "\n[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(port) + "\"]\n";
  return s;
}

TEST(DaemonSignals, SighupRefusesABadConfigAndTakesAGoodOneInANewSession) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const fs::path config = dir / "posefaird.toml";
  write_text(config, synthetic_config(poses.port(), false));
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 20 || !d.running(); }, 20s)) << d.err();
  ASSERT_TRUE(d.running()) << d.err();
  const auto first = poses.all();
  const std::uint32_t session = first.front().m.session;

  // A bad file: refused, the running configuration kept.
  std::string bad = synthetic_config(poses.port(), true);
  bad += "[engine]\nwindow = \"x\"\n";
  write_text(config, bad);
  const std::size_t before_bad = poses.count(1);
  d.send_signal(SIGHUP);
  ASSERT_TRUE(wait_for_log_or_exit(d, "reload refused, keeping the running configuration", 15s)) << d.err();
  EXPECT_NE(d.err().find("engine.window"), std::string::npos) << "the refusal names the key: " << d.err();
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= before_bad + 40 || !d.running(); }, 20s)) << d.err();
  ASSERT_TRUE(d.running()) << d.err();
  EXPECT_EQ(poses.count(2), 0u) << "the refused config's stream 2 must not run";
  EXPECT_EQ(count_of(d.err(), "reloaded:"), 0u) << d.err();

  // A good file with a second stream: taken.
  write_text(config, synthetic_config(poses.port(), true));
  const std::size_t before_good = poses.count(1);
  d.send_signal(SIGHUP);
  ASSERT_TRUE(wait_for_log_or_exit(d, "reloaded: 2 streams, 1 outputs", 15s)) << d.err();
  // Counted in the new session: stream 1's poses of the old one may still arrive after the
  // signal, and counting them would end the wait before the new session has sent 40.
  const auto in_new_session = [&](std::uint32_t stream) {
    return poses.count_if([&](const daemon::PoseMessage& m) { return m.stream == stream && m.session != session; });
  };
  ASSERT_TRUE(wait_until([&] { return (in_new_session(1) >= 40 && in_new_session(2) >= 40) || !d.running(); }, 20s))
      << d.err();
  ASSERT_TRUE(d.running()) << d.err();

  d.send_signal(SIGTERM);
  const auto t_term = Clock::now();
  const auto rc = d.wait(15s);
  ASSERT_EQ(rc, 0) << d.err();
  EXPECT_LT(Clock::now() - t_term, 5s) << "SIGTERM took too long";
  EXPECT_NE(d.err().find("SIGTERM: draining and stopping"), std::string::npos) << d.err();

  const auto all = poses.all();
  EXPECT_EQ(poses.malformed(), 0u);
  // The refused reload changed nothing: the first session runs until the good reload, which
  // starts a new session (windows and sources restart, docs/operations.md). Within each
  // session every stream's sequence starts at 0 and counts up by one per pose.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint64_t>> seqs;
  std::vector<std::uint32_t> sessions;
  for (const auto& g : all) {
    EXPECT_TRUE(g.m.stream == 1 || g.m.stream == 2) << g.m.stream;
    seqs[{g.m.session, g.m.stream}].push_back(g.m.sequence);
    if (sessions.empty() || sessions.back() != g.m.session) sessions.push_back(g.m.session);
  }
  ASSERT_EQ(sessions.size(), 2u) << "one session before the good reload, one after";
  EXPECT_EQ(sessions[0], session);
  EXPECT_NE(sessions[1], session);
  const auto& s1_before = seqs[std::make_pair(sessions[0], 1u)];
  ASSERT_GE(s1_before.size(), before_good) << "the refused reload must not have restarted stream 1";
  EXPECT_EQ(seqs.count(std::make_pair(sessions[0], 2u)), 0u) << "stream 2 runs only after the good reload";
  for (const auto& [key, seq] : seqs) {
    ASSERT_FALSE(seq.empty());
    EXPECT_EQ(seq.front(), 0u) << "session " << key.first << " stream " << key.second;
    std::size_t gaps = 0;
    for (std::size_t i = 1; i < seq.size(); ++i) {
      ASSERT_GT(seq[i], seq[i - 1]) << "session " << key.first << " stream " << key.second << " at pose " << i;
      gaps += seq[i] != seq[i - 1] + 1;
    }
    // Loopback with a 4 MiB buffer at 400 poses/s loses nothing: a gap is the daemon's.
    EXPECT_EQ(gaps, 0u) << "session " << key.first << " stream " << key.second;
  }
  ASSERT_GE(seqs[std::make_pair(sessions[1], 1u)].size(), 40u);
  ASSERT_GE(seqs[std::make_pair(sessions[1], 2u)].size(), 40u);
  // The daemon's final counters agree with what arrived after the reload.
  const auto c1 = last_counters(d.err(), "one", 1);
  const auto c2 = last_counters(d.err(), "two", 2);
  ASSERT_TRUE(c1 && c2) << d.err();
  EXPECT_EQ(c1->published, seqs[std::make_pair(sessions[1], 1u)].size()) << c1->line;
  EXPECT_EQ(c2->published, seqs[std::make_pair(sessions[1], 2u)].size()) << c2->line;
}

TEST(DaemonSignals, SighupWithAFixedSessionIdContinuesTheSequence) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const fs::path config = dir / "posefaird.toml";
  const std::string text = "[daemon]\nsession_id = 4242\n" + synthetic_config(poses.port(), false);
  write_text(config, text);
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 20 || !d.running(); }, 20s)) << d.err();
  const std::size_t before = poses.count(1);
  d.send_signal(SIGHUP);
  ASSERT_TRUE(wait_for_log_or_exit(d, "reloaded:", 15s)) << d.err();
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= before + 40 || !d.running(); }, 20s)) << d.err();
  d.send_signal(SIGTERM);
  ASSERT_EQ(d.wait(15s), 0) << d.err();
  const auto all = poses.all();
  ASSERT_GE(all.size(), before + 40);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].m.session, 4242u);
    EXPECT_EQ(all[i].m.sequence, i) << "the sequence continues across the reload without a gap or restart";
  }
}

// docs/protocol.md: the sample time is "monotonic within a session". A reload builds new
// drivers, and a synthetic or replay driver starts its times again from the beginning: so the
// reload must start a new session.
TEST(DaemonSignals, SighupKeepsEachStreamsSampleTimeMonotonicWithinTheSession) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const fs::path config = dir / "posefaird.toml";
  write_text(config, synthetic_config(poses.port(), false));
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 100 || !d.running(); }, 20s)) << d.err();
  const std::size_t before = poses.count(1);
  d.send_signal(SIGHUP);  // the same file again
  ASSERT_TRUE(wait_for_log_or_exit(d, "reloaded:", 15s)) << d.err();
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= before + 40 || !d.running(); }, 20s)) << d.err();
  d.send_signal(SIGTERM);
  ASSERT_EQ(d.wait(15s), 0) << d.err();
  const auto all = poses.all();
  ASSERT_FALSE(all.empty());
  for (std::size_t i = 1; i < all.size(); ++i) {
    if (all[i].m.session != all[i - 1].m.session) continue;
    ASSERT_GT(all[i].m.sample_time, all[i - 1].m.sample_time)
        << "session " << all[i].m.session << " seq " << all[i - 1].m.sequence << " -> " << all[i].m.sequence;
  }
}

// ---------------------------------------------------------------------------------------------
// 4. and 5. Recordings

TEST(DaemonRecording, SigtermWhileRecordingThenReplayTheRecording) {
  ScratchDir dir("posefair-e2e-");
  const fs::path recording = dir / "live.pflog";
  const fs::path config = dir / "record.toml";
  write_text(config,
             "[logging]\nstatus_interval = 0\n\n"
             "[[stream]]\nid = 3\nname = \"rec\"\n"
             "driver = { type = \"synthetic\", rate_hz = 500.0, duration = 0.0, with_position = true }\n\n"
             "[recorder]\npath = \"live.pflog\"\nflush_interval = 0.2\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_for_log_or_exit(d, "started:", 20s)) << d.err();
  std::this_thread::sleep_for(1s);
  ASSERT_TRUE(d.running()) << d.err();
  d.send_signal(SIGTERM);
  ASSERT_EQ(d.wait(20s), 0) << d.err();
  const auto c = last_counters(d.err(), "rec", 3);
  ASSERT_TRUE(c) << d.err();
  EXPECT_GT(c->received, 200u) << c->line;
  EXPECT_EQ(c->recorded, c->received) << c->line;
  EXPECT_EQ(c->record_dropped, 0u) << c->line;

  const formats::SampleLogContents log = formats::read_sample_log(recording);
  EXPECT_TRUE(log.stats.problems.empty()) << log.stats.problems.front().message;
  ASSERT_EQ(log.header.streams.size(), 1u);
  EXPECT_EQ(log.header.streams[0].id, 3u);
  EXPECT_EQ(log.header.streams[0].name, "rec");
  EXPECT_EQ(log.samples.size(), c->received) << c->line;
  for (std::size_t i = 0; i < log.samples.size(); ++i) {
    ASSERT_EQ(log.samples[i].stream_id, 3u) << i;
    if (i > 0) {
      ASSERT_GT(log.samples[i].time, log.samples[i - 1].time) << i;
    }
  }

  // The recording played back through a second daemon: every sample is emitted.
  const fs::path replay = dir / "replay.toml";
  write_text(replay,
             "[daemon]\nexit_when_sources_end = true\n\n[logging]\nstatus_interval = 0\n\n"
             "[[stream]]\nid = 3\nname = \"rec\"\nring_capacity = 65536\n"
             "driver = { type = \"replay\", path = \"live.pflog\", timing = \"fast\" }\n");
  Subprocess r(daemon_args(replay), dir / "r.out", dir / "r.err");
  ASSERT_EQ(r.wait(30s), 0) << r.err();
  EXPECT_NE(r.err().find("every source has ended"), std::string::npos) << r.err();
  EXPECT_EQ(count_of(r.err(), "warning"), 0u) << r.err();
  const auto rc = last_counters(r.err(), "rec", 3);
  ASSERT_TRUE(rc) << r.err();
  EXPECT_EQ(rc->received, c->received) << rc->line;
  EXPECT_EQ(rc->dropped, 0u) << rc->line;
  EXPECT_EQ(rc->emitted, c->received) << rc->line;
}

// A reload that leaves [recorder] and the stream table alone keeps writing the same file (the
// open writer is handed to the new pipeline): one recording holds the samples of both.
TEST(DaemonRecording, SighupWithTheSameRecorderContinuesTheRecording) {
  ScratchDir dir("posefair-e2e-");
  const fs::path config = dir / "record.toml";
  const std::string text =
      "[logging]\nstatus_interval = 0\n\n"
      "[[stream]]\nid = 4\nname = \"rec\"\n"
      "driver = { type = \"synthetic\", rate_hz = 500.0, duration = 0.0 }\n\n"
      "[recorder]\npath = \"both.pflog\"\nflush_interval = 0.2\n";
  write_text(config, text);
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_for_log_or_exit(d, "started:", 20s)) << d.err();
  std::this_thread::sleep_for(500ms);
  d.send_signal(SIGHUP);
  ASSERT_TRUE(wait_for_log_or_exit(d, "reloaded:", 15s)) << d.err();
  std::this_thread::sleep_for(500ms);
  d.send_signal(SIGTERM);
  ASSERT_EQ(d.wait(20s), 0) << d.err();
  // The counter lines: one when the first pipeline stopped at the reload, one at exit.
  std::uint64_t received = 0, lines = 0;
  for (const std::string& line : lines_of(d.err())) {
    const auto at = line.find("stream rec (id 4, ");
    if (at == std::string::npos) continue;
    const auto r = line.find("): received ", at);
    ASSERT_NE(r, std::string::npos) << line;
    received += std::stoull(line.substr(r + 12));
    ++lines;
  }
  ASSERT_EQ(lines, 2u) << d.err();
  const formats::SampleLogContents log = formats::read_sample_log(dir / "both.pflog");
  EXPECT_TRUE(log.stats.problems.empty());
  EXPECT_EQ(log.samples.size(), received) << "one file holds every sample of both pipelines";
  EXPECT_FALSE(fs::exists(dir / "both.1.pflog"));
}

// A '%' in the recorder's path is expanded by strftime, so a restarted service starts a new file.
TEST(DaemonRecording, ATimePatternInTheRecorderPathNamesTheFile) {
  ScratchDir dir("posefair-e2e-");
  const fs::path config = dir / "record.toml";
  write_text(config,
             "[daemon]\nexit_when_sources_end = true\n[logging]\nstatus_interval = 0\n\n"
             "[[stream]]\nid = 6\nname = \"rec\"\n"
             "driver = { type = \"synthetic\", rate_hz = 1000.0, duration = 0.2 }\n\n"
             "[recorder]\npath = \"run-%Y%m%d.pflog\"\nsync = false\n");
  const std::time_t now = std::time(nullptr);
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_EQ(d.wait(30s), 0) << d.err();
  std::tm local{};
  ::localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof name, "run-%Y%m%d.pflog", &local);
  ASSERT_TRUE(fs::exists(dir / name)) << "expected " << name << "; " << d.err();
  EXPECT_FALSE(fs::exists(dir / "run-%Y%m%d.pflog"));
  EXPECT_EQ(formats::read_sample_log(dir / name).samples.size(), 200u);
}

TEST(DaemonRecording, ATruncatedRecordingIsPlayedUpToTheDamageWithAWarning) {
  ScratchDir dir("posefair-e2e-");
  // A recording of the demo file, made by the daemon's recorder.
  const fs::path recording = dir / "demo.pflog";
  const fs::path config = dir / "record.toml";
  write_text(config, "[daemon]\nexit_when_sources_end = true\n\n[logging]\nstatus_interval = 0\n\n"
                     "[[stream]]\nid = 5\nname = \"demo\"\nring_capacity = 4096\n"
                     "driver = { type = \"replay\", path = \"" +
                         kDemoCsv.string() +
                         "\", timing = \"fast\" }\n\n"
                         "[recorder]\npath = \"demo.pflog\"\nsync = false\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_EQ(d.wait(30s), 0) << d.err();
  const auto c = last_counters(d.err(), "demo", 5);
  ASSERT_TRUE(c) << d.err();
  ASSERT_EQ(c->recorded, kDemoSamples) << c->line;
  {
    const auto whole = formats::read_sample_log(recording);
    ASSERT_TRUE(whole.stats.problems.empty());
    ASSERT_EQ(whole.samples.size(), kDemoSamples);
  }

  // Cut off the last 50 bytes: the last record is no longer whole.
  fs::resize_file(recording, fs::file_size(recording) - 50);
  const auto cut = formats::read_sample_log(recording);
  ASSERT_EQ(cut.stats.problems.size(), 1u);
  const std::uint64_t offset = cut.stats.problems[0].offset;
  const std::size_t intact = cut.samples.size();
  EXPECT_EQ(intact, kDemoSamples - 1);

  const fs::path replay = dir / "replay.toml";
  write_text(replay,
             "[daemon]\nexit_when_sources_end = true\n\n[logging]\nstatus_interval = 0\n\n"
             "[[stream]]\nid = 5\nname = \"demo\"\nring_capacity = 4096\n"
             "driver = { type = \"replay\", path = \"demo.pflog\", timing = \"fast\" }\n");
  Subprocess r(daemon_args(replay), dir / "r.out", dir / "r.err");
  ASSERT_EQ(r.wait(30s), 0) << r.err();
  const std::string log = r.err();
  bool warned = false;
  for (const std::string& line : lines_of(log))
    warned = warned || (line.find(" warning: ") != std::string::npos &&
                        line.find("offset " + std::to_string(offset)) != std::string::npos);
  EXPECT_TRUE(warned) << "no warning naming offset " << offset << ":\n" << log;
  std::printf("replay of the truncated recording (%zu intact samples, damage at offset %llu):\n%s", intact,
              static_cast<unsigned long long>(offset), log.c_str());
  const auto rc = last_counters(log, "demo", 5);
  ASSERT_TRUE(rc) << log;
  EXPECT_EQ(rc->received, intact) << rc->line;
  EXPECT_EQ(rc->emitted, intact) << rc->line;
}

// ---------------------------------------------------------------------------------------------
// 6. Malformed configs through the real binary

struct BadRow {
  const char* name;
  std::string toml;
  std::string at;   // text of the offending line (its line number is computed from it)
  std::string key;  // must appear in the message ("" for a syntax error: toml++ names no key)
};

std::uint32_t line_of(const std::string& toml, const std::string& at) {
  const auto p = toml.find(at);
  if (p == std::string::npos) throw std::logic_error("row text not found: " + at);
  return static_cast<std::uint32_t>(1 + std::count(toml.begin(), toml.begin() + static_cast<std::ptrdiff_t>(p), '\n'));
}

// A config that would end by itself at once if it were (wrongly) accepted.
const std::string kPrelude = "[daemon]\nexit_when_sources_end = true\n\n";
const std::string kStream1 = "[[stream]]\nid = 1\nname = \"a\"\ndriver = { type = \"synthetic\", duration = 0.1 }\n";

std::vector<BadRow> bad_rows() {
  return {
      {"syntax error", kPrelude + kStream1 + "[stream.engine]\nwindow = = 16\n", "window = = 16", ""},
      {"unknown key", kPrelude + "[engine]\nwindw = 16\n\n" + kStream1, "windw = 16", "engine.windw"},
      {"bad value", kPrelude + kStream1 + "[stream.engine]\nwindow = \"x\"\n", "window = \"x\"",
       "stream[1].engine.window"},
      {"missing replay file",
       kPrelude + "[[stream]]\nid = 1\nname = \"a\"\n[stream.driver]\ntype = \"replay\"\npath = \"no-such-file.csv\"\n",
       "path = \"no-such-file.csv\"", "stream[1].driver.path"},
      {"duplicate stream id",
       kPrelude + kStream1 + "\n[[stream]]\nid = 1 # again\nname = \"b\"\ndriver = { type = \"synthetic\" }\n",
       "id = 1 # again", "stream[2].id"},
      {"ring capacity not a power of two", kPrelude + "[[stream]]\nid = 1\nname = \"a\"\nring_capacity = 1000\n"
                                                      "driver = { type = \"synthetic\", duration = 0.1 }\n",
       "ring_capacity = 1000", "stream[1].ring_capacity"},
      {"lag not below window", kPrelude + kStream1 + "[stream.engine]\nwindow = 8\nlag = 8\n", "lag = 8",
       "stream[1].engine.lag"},
      {"unknown encoding", kPrelude + kStream1 + "\n[[output]]\nencoding = \"osc\"\ndestinations = [\"127.0.0.1:9\"]\n",
       "encoding = \"osc\"", "output[1].encoding"},
      {"vrchat tracker out of range",
       kPrelude + kStream1 + "\n[[output]]\nencoding = \"vrchat\"\ndestinations = [\"127.0.0.1:9\"]\ntrackers = [9]\n",
       "trackers = [9]", "output[1].trackers[1]"},
      {"not a Unity bone",
       kPrelude + kStream1 + "\n[[output]]\nencoding = \"vmc\"\ndestinations = [\"127.0.0.1:9\"]\nbones = [\"Pelvis\"]\n",
       "bones = [\"Pelvis\"]", "output[1].bones[1]"},
      {"mounting not a rotation", kPrelude + "[[stream]]\nid = 1\nname = \"a\"\nmounting = [0, 90]\n"
                                             "driver = { type = \"synthetic\", duration = 0.1 }\n",
       "mounting = [0, 90]", "stream[1].mounting"},
  };
}

TEST(DaemonConfigErrors, MalformedConfigsExit78WithFileLineAndKey) {
  ScratchDir dir("posefair-e2e-");
  int n = 0;
  for (const BadRow& row : bad_rows()) {
    SCOPED_TRACE(row.name);
    const fs::path file = dir / ("bad-" + std::to_string(++n) + ".toml");
    write_text(file, row.toml);
    const std::string where = file.string() + ":" + std::to_string(line_of(row.toml, row.at)) + ":";
    for (const bool check : {true, false}) {
      SCOPED_TRACE(check ? "--check" : "run");
      std::vector<std::string> args = daemon_args(file);
      if (check) args.push_back("--check");
      Subprocess p(args, dir / "out", dir / "err");
      const auto rc = p.wait(20s);
      const std::string err = p.err();
      EXPECT_EQ(rc, kExitConfig) << err;
      EXPECT_NE(err.find(where), std::string::npos) << "expected '" << where << "' in: " << err;
      if (!row.key.empty()) {
        EXPECT_NE(err.find(row.key + ":"), std::string::npos) << row.key << " not in: " << err;
      }
      EXPECT_EQ(p.out(), "");
    }
  }
}

TEST(DaemonConfigErrors, AGoodConfigPassesTheCheck) {
  ScratchDir dir("posefair-e2e-");
  const fs::path file = dir / "good.toml";
  write_text(file, kPrelude + kStream1 +
                       "[stream.engine]\nwindow = 8\nlag = 7\n\n[[output]]\ndestinations = [\"127.0.0.1:9\"]\n");
  Subprocess p({kPosefaird, "--check", "-c", file.string()}, dir / "out", dir / "err");
  ASSERT_EQ(p.wait(20s), 0) << p.err();
  EXPECT_NE(p.out().find(file.string() + ": ok (1 streams, 1 outputs)"), std::string::npos) << p.out();
}

// ---------------------------------------------------------------------------------------------
// 7. The client encodings (docs/outputs.md) from a running daemon

double le_double(const std::vector<std::uint8_t>& d, std::size_t at) {
  std::uint64_t bits = 0;
  for (int b = 7; b >= 0; --b) bits = (bits << 8) | d[at + static_cast<std::size_t>(b)];
  double v = 0;
  std::memcpy(&v, &bits, 8);
  return v;
}

bool contains(const std::vector<std::uint8_t>& d, std::string_view text) {
  return std::search(d.begin(), d.end(), text.begin(), text.end()) != d.end();
}

TEST(DaemonClientEncodings, EveryEncodingCarriesItsStreamWithTheStreamsMounting) {
  ScratchDir dir("posefair-e2e-");
  Collector binary;
  RawUdpCollector opentrack, freed, vmc, vrchat;
  auto to = [](std::uint16_t port) { return "destinations = [\"127.0.0.1:" + std::to_string(port) + "\"]\n"; };
  const fs::path config = dir / "clients.toml";
  write_text(config, "[daemon]\nexit_when_sources_end = true\n[logging]\nstatus_interval = 0\n\n"
                     "[[stream]]\nid = 1\nname = \"head\"\nmounting = [-90, 0, 0]\n"
                     "driver = { type = \"synthetic\", rate_hz = 200.0, duration = 1.0, with_position = true }\n"
                     "[[stream]]\nid = 2\nname = \"hips\"\n"
                     "driver = { type = \"synthetic\", rate_hz = 200.0, duration = 1.0, seed = 2 }\n\n"
                     "[[output]]\n" + to(binary.port()) +
                     "[[output]]\nencoding = \"opentrack\"\nstreams = [1]\n" + to(opentrack.port()) +
                     "[[output]]\nencoding = \"freed\"\nstreams = [2]\nmax_rate_hz = 20\nzoom = 77\n" + to(freed.port()) +
                     "[[output]]\nencoding = \"vmc\"\nbones = [\"Head\", \"Hips\"]\n" + to(vmc.port()) +
                     "[[output]]\nencoding = \"vrchat\"\ntrackers = [\"head\", 1]\n" + to(vrchat.port()));
  Subprocess d(daemon_args(config), dir / "out", dir / "err");
  ASSERT_EQ(d.wait(30s), 0) << d.err();
  binary.drain();
  ASSERT_TRUE(wait_until([&] { return opentrack.datagrams().size() >= binary.count(1); }, 5s));

  // opentrack: stream 1 only, every pose, each the binary pose's angles (the mounting applied
  // once, before both encodings).
  std::vector<daemon::PoseMessage> head;
  for (const daemon::PoseMessage& m : binary.messages())
    if (m.stream == 1) head.push_back(m);
  const auto ot = opentrack.datagrams();
  ASSERT_GT(head.size(), 100u);
  ASSERT_EQ(ot.size(), head.size());
  for (std::size_t i = 0; i < ot.size(); i += 37) {
    ASSERT_EQ(ot[i].size(), 48u);
    const daemon::HeadAngles a = daemon::head_angles(head[i].orientation);
    EXPECT_NEAR(le_double(ot[i], 24), a.yaw, 1e-9) << "pose " << i;
    EXPECT_NEAR(le_double(ot[i], 32), a.pitch, 1e-9) << "pose " << i;
    EXPECT_NEAR(le_double(ot[i], 0), -100.0 * head[i].position->y(), 1e-9) << "pose " << i;
  }

  // freed: stream 2 at most 20 a second over 1 s, each a valid D1 message with zoom 77.
  const auto fd = freed.datagrams();
  EXPECT_GE(fd.size(), 15u);
  EXPECT_LE(fd.size(), 21u);
  for (const auto& m : fd) {
    ASSERT_EQ(m.size(), 29u);
    EXPECT_EQ(m[0], 0xD1);
    EXPECT_EQ(m[1], 2);  // the stream's id is its camera id
    unsigned sum = 0;
    for (std::uint8_t b : m) sum += b;
    EXPECT_EQ(sum % 256, 0x40u);
    EXPECT_EQ(m[22], 77);
  }

  // vmc and vrchat: one OSC bundle per pose of either stream, to its bone or tracker.
  const std::size_t poses = binary.count(1) + binary.count(2);
  const auto vm = vmc.datagrams();
  const auto vr = vrchat.datagrams();
  EXPECT_EQ(vm.size(), poses);
  EXPECT_EQ(vr.size(), poses);
  std::size_t heads = 0, hips = 0, head_tracker = 0, tracker1 = 0;
  for (const auto& b : vm) {
    EXPECT_TRUE(contains(b, "#bundle"));
    EXPECT_TRUE(contains(b, "/VMC/Ext/Bone/Pos"));
    heads += contains(b, "Head");
    hips += contains(b, "Hips");
  }
  for (const auto& b : vr) {
    head_tracker += contains(b, "/tracking/trackers/head/rotation");
    tracker1 += contains(b, "/tracking/trackers/1/rotation") && !contains(b, "/tracking/trackers/1/position");
  }
  EXPECT_EQ(heads, binary.count(1));
  EXPECT_EQ(hips, binary.count(2));
  EXPECT_EQ(head_tracker, binary.count(1));
  EXPECT_EQ(tracker1, binary.count(2));  // stream 2 has no position: rotation only
}

// ---------------------------------------------------------------------------------------------
// 8. posefair sub --idle

TEST(SubIdle, ExitsAboutIdleSecondsAfterTheLastDatagram) {
  ScratchDir dir("posefair-e2e-");
  Subprocess sub({kPosefair, "sub", "--listen", "127.0.0.1:0", "--idle", "1", "--duration", "30", "--quiet"},
                 dir / "out", dir / "err");
  const auto port = sub.wait_for_listening_port(20s);
  ASSERT_TRUE(port) << sub.err();
  // The idle clock starts with the first datagram, not at start.
  std::this_thread::sleep_for(1500ms);
  ASSERT_TRUE(sub.running()) << "exited before any datagram came: " << sub.err();

  daemon::UdpSocket sender = daemon::UdpSocket::open(AF_INET);
  const daemon::Endpoint to = *daemon::Endpoint::parse("127.0.0.1:" + std::to_string(*port));
  Clock::time_point last_sent;
  for (std::uint64_t i = 0; i < 6; ++i) {
    daemon::PoseMessage m;
    m.session = 7;
    m.stream = 1;
    m.sequence = i;
    m.sample_time = 0.1 * static_cast<double>(i);
    const auto bytes = daemon::encode_binary(m);
    ASSERT_TRUE(sender.send_to(bytes, to));
    last_sent = Clock::now();
    std::this_thread::sleep_for(300ms);  // shorter than --idle: it keeps running
    ASSERT_TRUE(sub.running()) << "exited " << i << " datagrams in: " << sub.err();
  }
  // 6 × 300 ms after the first datagram is beyond the idle second: only the latest counts.
  ASSERT_TRUE(wait_until([&] { return !sub.running(); }, 15s)) << "still running 15 s after the last datagram";
  const double after = std::chrono::duration<double>(Clock::now() - last_sent).count();
  EXPECT_GE(after, 0.9) << "exited too early";
  EXPECT_LE(after, 4.0) << "exited too late";
  EXPECT_EQ(sub.wait(1s), 0) << sub.err();
  EXPECT_NE(sub.err().find("stats: received 6, lost 0"), std::string::npos) << sub.err();
}

}  // namespace
}  // namespace posefair::testing

// ---------------------------------------------------------------------------------------------
// 8. systemd: READY=1, STATUS=, WATCHDOG=1, STOPPING=1 through a NOTIFY_SOCKET of the test's
//    own (sd_notify's protocol: one datagram per message to an AF_UNIX socket); SIGUSR1 logs
//    the counters.

namespace posefair::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class NotifySocket {
 public:
  explicit NotifySocket(const fs::path& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error("socket(AF_UNIX)");
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) throw std::runtime_error("bind " + path.string());
  }
  ~NotifySocket() { ::close(fd_); }
  // Every message that arrives within `timeout`, in order.
  std::vector<std::string> drain(std::chrono::milliseconds timeout) {
    std::vector<std::string> got;
    const auto deadline = Clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) return got;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n > 0) got.emplace_back(buf, static_cast<std::size_t>(n));
    }
  }

 private:
  fs::path path_;
  int fd_ = -1;
};

TEST(DaemonSystemd, NotifiesReadyStatusWatchdogAndStoppingAndLogsCountersOnSigusr1) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const fs::path config = dir / "posefaird.toml";
  write_text(config, synthetic_config(poses.port(), false));
  NotifySocket notify(dir / "notify.sock");
  // The child inherits the environment: set it for the spawn only.
  ::setenv("NOTIFY_SOCKET", (dir / "notify.sock").c_str(), 1);
  ::setenv("WATCHDOG_USEC", "400000", 1);  // 0.4 s: posefaird pets it every 0.1 s
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");

  std::vector<std::string> messages = notify.drain(2500ms);
  ASSERT_TRUE(d.running()) << d.err();
  auto count = [&](const std::string& prefix) {
    return std::count_if(messages.begin(), messages.end(), [&](const std::string& m) { return m.find(prefix) != std::string::npos; });
  };
  EXPECT_GE(count("READY=1"), 1) << "no READY=1";
  EXPECT_GE(count("WATCHDOG=1"), 5) << "the watchdog is petted every quarter of WATCHDOG_USEC";
  // STATUS= once a second with the stream's name, its rate and drops.
  bool status_with_rate = false;
  for (const std::string& m : messages)
    if (m.rfind("STATUS=one ", 0) == 0 && m.find("/s drop 0 p99 ") != std::string::npos) status_with_rate = true;
  EXPECT_TRUE(status_with_rate) << "no STATUS= line with the stream's rate; got " << messages.size() << " messages";

  d.send_signal(SIGUSR1);
  EXPECT_TRUE(wait_for_log_or_exit(d, "stream one (id 1, synthetic:200Hz): received ", 5s)) << d.err();
  EXPECT_TRUE(d.running());

  d.send_signal(SIGTERM);
  ASSERT_EQ(d.wait(15s), 0) << d.err();
  const std::vector<std::string> last = notify.drain(200ms);
  EXPECT_TRUE(std::any_of(last.begin(), last.end(), [](const std::string& m) { return m.find("STOPPING=1") != std::string::npos; }))
      << "no STOPPING=1 at SIGTERM";
}

}  // namespace
}  // namespace posefair::testing

// ---------------------------------------------------------------------------------------------
// 9. A serial device: a golden replay log (tests/replay/) written into a pseudo-terminal that
//    the daemon's serial stream opens through a symlink, at the device's pace; the device's
//    link appears in the counter line and in STATUS=, and an unplug is counted and reported.

namespace posefair::testing {
namespace {

TEST(DaemonSerial, AGoldenLogThroughAPtyIsFairedAndTheLinkIsReported) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const replay::ReplayLog log = replay::read_replay_log(fs::path(POSEFAIR_SOURCE_DIR) / "tests/replay/posefair-text.log");
  auto pty = std::make_unique<PseudoTerminal>();
  const fs::path link = dir / "ttyPF";
  fs::create_symlink(pty->slave(), link);
  const fs::path config = dir / "posefaird.toml";
  write_text(config, "[logging]\nstatus_interval = 0\n\n[[stream]]\nid = 1\nname = \"imu\"\n"
                     "driver = { type = \"serial\", device = \"" + link.string() +
                     "\", protocol = \"posefair\", reconnect_min = 0.05, reconnect_max = 0.2 }\n\n"
                     "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(poses.port()) + "\"]\n");
  NotifySocket notify(dir / "notify.sock");
  ::setenv("NOTIFY_SOCKET", (dir / "notify.sock").c_str(), 1);
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ::unsetenv("NOTIFY_SOCKET");
  ASSERT_TRUE(wait_for_log_or_exit(d, "opened ", 10s)) << d.err();

  // 300 frames at about 95 Hz, as the device would send them.
  const std::size_t chunk = log.data.size() / 300 + 1;
  for (std::size_t at = 0; at < log.data.size(); at += chunk) {
    pty->write(std::string_view(log.data).substr(at, chunk));
    std::this_thread::sleep_for(10ms);
  }
  // The .chk says 288 samples survive the log's faults; all but the lag's tail are faired.
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 280 || !d.running(); }, 10s)) << d.err();
  d.send_signal(SIGUSR1);
  ASSERT_TRUE(wait_for_log_or_exit(d, "; device connected, outages 0, reconnects 0", 5s)) << d.err();
  EXPECT_NE(d.err().find("stream imu (id 1, serial:" + link.string() + " (posefair)): received 288 ("), std::string::npos)
      << d.err();
  EXPECT_NE(d.err().find(", frames 288, bad 9, resyncs 14 (skipped 3871 bytes)"), std::string::npos) << d.err();

  // Unplug: the stream stays, the outage is logged once and shown in STATUS= and the counters.
  // udev removes the device's link with it: pointed nowhere, so that the daemon's reopening
  // cannot find a pty another test opens under the reused /dev/pts number (run beside
  // SerialDriver.UnplugAndReplug…, it did, and counted a reconnect).
  fs::remove(link);
  fs::create_symlink(dir / "unplugged", link);
  pty.reset();
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream 'imu': lost the device", 5s)) << d.err();
  const std::vector<std::string> messages = notify.drain(2500ms);
  EXPECT_TRUE(std::any_of(messages.begin(), messages.end(), [](const std::string& m) {
    return m.rfind("STATUS=imu ", 0) == 0 && m.find(" DISCONNECTED outages 1 bad 9") != std::string::npos;
  })) << "no STATUS= with the outage; got " << messages.size() << " messages";
  d.send_signal(SIGUSR1);
  ASSERT_TRUE(wait_for_log_or_exit(d, "; device DISCONNECTED, outages 1, reconnects 0", 5s)) << d.err();
  EXPECT_TRUE(d.running());
  d.send_signal(SIGTERM);
  EXPECT_EQ(d.wait(15s), 0) << d.err();
}

}  // namespace
}  // namespace posefair::testing

// ---------------------------------------------------------------------------------------------
// 10. [stream.spline]: a replayed recording with a short and a long gap, published at 250 Hz.
//     The short gap is bridged on the spline (the window does not restart, the poses across it
//     are flagged bridged); the long one restarts the window and the grid (no pose inside it);
//     every pose lies on the 250 Hz grid.

namespace posefair::testing {
namespace {

// The demo excerpt (285.7 Hz) without rows 500..519 (70 ms) and 1200..1299 (350 ms).
struct DemoWithGaps {
  std::string csv;
  std::vector<double> kept_times;
  double short_from, short_to, long_from, long_to;
};
DemoWithGaps demo_with_gaps() {
  const std::vector<std::string> rows = lines_of(slurp(kDemoCsv));
  DemoWithGaps g;
  g.csv = rows[0] + "\n";
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const std::size_t r = i - 1;
    if ((r >= 500 && r < 520) || (r >= 1200 && r < 1300)) continue;
    g.csv += rows[i] + "\n";
    g.kept_times.push_back(std::stod(rows[i]));
  }
  g.short_from = std::stod(rows[500]), g.short_to = std::stod(rows[521]);  // rows 499 and 520
  g.long_from = std::stod(rows[1200]), g.long_to = std::stod(rows[1301]);  // rows 1199 and 1300
  return g;
}

TEST(DaemonSpline, AReplayWithGapsIsBridgedAndPublishedOnA250HzGrid) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const DemoWithGaps g = demo_with_gaps();
  const std::vector<double>& kept_times = g.kept_times;
  const double short_from = g.short_from, short_to = g.short_to, long_from = g.long_from, long_to = g.long_to;
  write_text(dir / "gaps.csv", g.csv);
  const fs::path config = dir / "posefaird.toml";
  write_text(config, "[daemon]\nexit_when_sources_end = true\n[logging]\nstatus_interval = 0\n\n"
                     "[[stream]]\nid = 1\nname = \"gaps\"\n"
                     "driver = { type = \"replay\", path = \"gaps.csv\", timing = \"original\", speed = 5.0 }\n"
                     "[stream.spline]\npublish_rate_hz = 250.0\nbridge_gap = 0.1\n\n"
                     "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(poses.port()) + "\"]\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_EQ(d.wait(60s), 0) << d.err();
  std::this_thread::sleep_for(200ms);  // the last datagrams in flight
  const auto all = poses.all();
  ASSERT_GT(all.size(), 1500u) << d.err();

  std::size_t bridged = 0, jumps = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const daemon::PoseMessage& m = all[i].m;
    const double t = m.sample_time;
    ASSERT_NEAR(t * 250.0, std::round(t * 250.0), 1e-6) << "pose " << i << " off the 250 Hz grid: " << t;
    EXPECT_FALSE(t > long_from + 1e-9 && t < long_to - 1e-9) << "pose " << i << " inside the long gap: " << t;
    if (m.bridged()) {
      ++bridged;
      EXPECT_GT(t, short_from - 0.004) << "a bridged pose away from the short gap";
      EXPECT_LT(t, short_to + 0.004) << "a bridged pose away from the short gap";
    }
    if (i > 0) {
      const double step = t - all[i - 1].m.sample_time;
      if (std::abs(step - 0.004) > 1e-9) {
        ++jumps;
        EXPECT_GT(step, 0.3) << "pose " << i << ": only the long gap breaks the grid";
      }
    }
  }
  EXPECT_EQ(jumps, 1u);
  // The 70 ms gap is 17 or 18 grid steps, all from bridged samples or their neighbours.
  EXPECT_GE(bridged, 17u);
  EXPECT_LE(bridged, 20u);
  // The grid covers the recording up to its end, less the resampler's delay.
  EXPECT_LT(all.front().m.sample_time - kept_times.front(), 0.02);
  EXPECT_LT(kept_times.back() - all.back().m.sample_time, 0.02);

  const auto counters = last_counters(d.err(), "gaps", 1);
  ASSERT_TRUE(counters) << d.err();
  EXPECT_EQ(counters->received, 2000u - 120u);
  EXPECT_EQ(counters->published, all.size()) << counters->line;
  // The short gap is bridged; the long one (over bridge_gap) is passed through, and counted.
  EXPECT_NE(counters->line.find(", bridged gaps 1 (samples 20, passed through 1), resampled " + std::to_string(all.size())), std::string::npos)
      << counters->line;
  EXPECT_NE(counters->line.find(", restarts 1,"), std::string::npos) << "only the long gap restarts the window: " << counters->line;
}

// pose_interpolation = "matrix-lerp": the same replay, bridged and resampled with Alexa's lerp of
// the 4x4 pose (the demo has positions). Nothing is held at the short gap, the grid reaches to
// within one input interval of the last faired pose, and the counter line shows no fallback.
TEST(DaemonSpline, MatrixLerpBridgesAndResamplesTheSameReplay) {
  ScratchDir dir("posefair-e2e-");
  Collector poses;
  const DemoWithGaps g = demo_with_gaps();
  write_text(dir / "gaps.csv", g.csv);
  const fs::path config = dir / "posefaird.toml";
  write_text(config, "[daemon]\nexit_when_sources_end = true\n[logging]\nstatus_interval = 0\n\n"
                     "[[stream]]\nid = 1\nname = \"gaps\"\n"
                     "driver = { type = \"replay\", path = \"gaps.csv\", timing = \"original\", speed = 5.0 }\n"
                     "[stream.spline]\npublish_rate_hz = 250.0\nbridge_gap = 0.1\npose_interpolation = \"matrix-lerp\"\n\n"
                     "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(poses.port()) + "\"]\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_EQ(d.wait(60s), 0) << d.err();
  std::this_thread::sleep_for(200ms);  // the last datagrams in flight
  const auto all = poses.all();
  ASSERT_GT(all.size(), 1500u) << d.err();
  std::size_t bridged = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const daemon::PoseMessage& m = all[i].m;
    const double t = m.sample_time;
    ASSERT_NEAR(t * 250.0, std::round(t * 250.0), 1e-6) << "pose " << i << " off the 250 Hz grid: " << t;
    EXPECT_FALSE(t > g.long_from + 1e-9 && t < g.long_to - 1e-9) << "pose " << i << " inside the long gap: " << t;
    EXPECT_TRUE(m.position.has_value()) << "pose " << i;
    if (m.bridged()) {
      ++bridged;
      EXPECT_GT(t, g.short_from - 0.004) << "a bridged pose away from the short gap";
      EXPECT_LT(t, g.short_to + 0.004) << "a bridged pose away from the short gap";
    }
  }
  EXPECT_GE(bridged, 17u);
  EXPECT_LE(bridged, 20u);
  const auto counters = last_counters(d.err(), "gaps", 1);
  ASSERT_TRUE(counters) << d.err();
  EXPECT_EQ(counters->published, all.size()) << counters->line;
  EXPECT_NE(counters->line.find(", bridged gaps 1 (samples 20, passed through 1), resampled " + std::to_string(all.size()) + ", lerp fallbacks 0"),
            std::string::npos)
      << counters->line;
  EXPECT_NE(counters->line.find(", restarts 1,"), std::string::npos) << "only the long gap restarts the window: " << counters->line;
}

}  // namespace
}  // namespace posefair::testing
