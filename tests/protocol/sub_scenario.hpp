#pragma once
// The traffic the subscriber tests send: one stream of 200 distinct poses (binary and JSON
// lines mixed, every flag combination) with 5 sequence numbers skipped, 3 pairs swapped, 2
// duplicates, and 10 malformed datagrams of 10 different kinds. Sent over 127.0.0.1 only.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "posefair/daemon/json_lines.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"
#include "protocol_samples.hpp"
#include "subprocess.hpp"

namespace posefair::testing {

using daemon::PoseMessage;
using Bytes = std::vector<std::uint8_t>;

struct Scenario {
  std::vector<Bytes> datagrams;      // in sending order
  std::vector<PoseMessage> poses;    // the valid ones, in sending (= loopback arrival) order
  std::uint64_t lost = 0, reordered = 0, duplicates = 0, malformed = 0;
  std::string malformed_reasons;     // as the stats line prints them
};

inline double realtime_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

inline PoseMessage scenario_pose(std::uint64_t seq, std::uint32_t session, std::uint32_t stream) {
  std::uint16_t flags = 0;
  if (seq % 2 == 0) flags |= daemon::kFlagPosition;
  if (seq % 3 == 0) flags |= daemon::kFlagAngularVelocity;
  if (seq % 5 == 0) flags |= daemon::kFlagClamped;
  if (seq % 7 == 0) flags |= daemon::kFlagBridged;
  PoseMessage m = daemon::testing::sample_message(flags, seq, session, stream);
  m.sample_time = 10.0 + static_cast<double>(seq) * 0.01;
  m.send_time = realtime_now();
  return m;
}

inline Bytes encode_for_scenario(const PoseMessage& m) {
  if (m.sequence % 4 == 1) {  // every fourth as a JSON line
    const std::string j = daemon::encode_json(m);
    return Bytes(j.begin(), j.end());
  }
  return daemon::encode_binary(m);
}

// The ten malformed datagrams, one of each kind, in DecodeError order.
inline std::vector<Bytes> malformed_datagrams() {
  const Bytes good = daemon::encode_binary(daemon::testing::sample_message(daemon::kFlagPosition, 1));
  auto patched = [&good](std::size_t at, std::uint8_t v) {
    Bytes d = good;
    d[at] = v;
    return d;
  };
  auto with_f64 = [&good](std::size_t at, double v) {
    Bytes d = good;
    const auto bits = std::bit_cast<std::uint64_t>(v);
    for (int i = 0; i < 8; ++i) d[at + i] = static_cast<std::uint8_t>(bits >> (8 * i));
    return d;
  };
  Bytes oversized = good;
  oversized.resize(1600, 0);
  Bytes longer = good;
  longer.push_back(0);
  const std::string text = "hello, posefair";
  const std::string broken_json = R"({"v":1,"session":1,)";
  return {
      Bytes{0x50, 0x46, 0x50, 0x31, 0x01},      // too-short
      oversized,                                // oversized
      Bytes(text.begin(), text.end()),          // bad-magic
      patched(4, 2),                            // bad-version
      patched(5, 40),                           // bad-header-length
      longer,                                   // length-mismatch
      patched(7, 0x02),                         // unknown-flags (bit 9)
      with_f64(24, std::bit_cast<double>(0x7FF8000000000000ULL)),  // non-finite (NaN sample time)
      with_f64(56, 2.0),                        // bad-quaternion
      Bytes(broken_json.begin(), broken_json.end()),  // json-syntax
  };
}

inline Scenario make_scenario(std::uint32_t session = 0xC0FFEE01u, std::uint32_t stream = 5) {
  // Sequence numbers 0..204 without 17, 18, 90, 91, 92 (lost 5): 200 poses.
  const std::set<std::uint64_t> skipped = {17, 18, 90, 91, 92};
  std::vector<std::uint64_t> order;
  for (std::uint64_t s = 0; s <= 204; ++s)
    if (!skipped.count(s)) order.push_back(s);
  // Three pairs swapped (reordered 3): 41 before 40, 121 before 120, 181 before 180.
  for (std::uint64_t s : {40, 120, 180}) {
    auto it = std::find(order.begin(), order.end(), s);
    std::iter_swap(it, it + 1);
  }
  // Two duplicates: 60 again right after itself, 140 again after 150.
  order.insert(std::find(order.begin(), order.end(), 60) + 1, 60);
  order.insert(std::find(order.begin(), order.end(), 150) + 1, 140);

  Scenario sc;
  std::vector<PoseMessage> by_seq(205);
  const auto bad = malformed_datagrams();
  std::size_t next_bad = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::uint64_t s = order[i];
    bool repeat = false;
    for (const auto& p : sc.poses) repeat = repeat || p.sequence == s;
    if (!repeat) by_seq[s] = scenario_pose(s, session, stream);
    sc.poses.push_back(by_seq[s]);
    sc.datagrams.push_back(encode_for_scenario(by_seq[s]));
    // A malformed datagram after every 15th pose, all of them well before the last pose.
    if (i % 15 == 7 && next_bad < bad.size()) sc.datagrams.push_back(bad[next_bad++]);
  }
  sc.lost = 5;
  sc.reordered = 3;
  sc.duplicates = 2;
  sc.malformed = bad.size();
  sc.malformed_reasons =
      "too-short 1, oversized 1, bad-magic 1, bad-version 1, bad-header-length 1, length-mismatch 1, "
      "unknown-flags 1, non-finite 1, bad-quaternion 1, json-syntax 1";
  return sc;
}

// A plain scenario: n poses in order, no faults.
inline Scenario make_clean_scenario(std::uint64_t n, std::uint32_t session = 0xC0FFEE02u, std::uint32_t stream = 6) {
  Scenario sc;
  for (std::uint64_t s = 0; s < n; ++s) {
    sc.poses.push_back(scenario_pose(s, session, stream));
    sc.datagrams.push_back(encode_for_scenario(sc.poses.back()));
  }
  return sc;
}

// Sends every datagram to 127.0.0.1:port, paced so a busy receiver's socket buffer never
// overflows (loopback keeps the order of one sender's datagrams).
inline void send_scenario(const Scenario& sc, std::uint16_t port) {
  daemon::UdpSocket tx = daemon::UdpSocket::open(AF_INET);
  const daemon::Endpoint to = *daemon::Endpoint::parse("127.0.0.1:" + std::to_string(port));
  for (const Bytes& d : sc.datagrams) {
    tx.send_to(d, to);
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
}

// The CSV row `posefair sub --format csv` prints for m, without the latency column's value.
inline std::string csv_row_without_latency(const PoseMessage& m) {
  char buf[1024];
  int n = std::snprintf(buf, sizeof buf, "%" PRIu32 ",%" PRIu32 ",%" PRIu64 ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                        m.session, m.stream, m.sequence, m.sample_time, m.send_time, m.orientation.w(),
                        m.orientation.x(), m.orientation.y(), m.orientation.z());
  std::string row(buf, static_cast<std::size_t>(n));
  for (const auto* v : {&m.position, &m.angular_velocity}) {
    if (*v) {
      n = std::snprintf(buf, sizeof buf, ",%.17g,%.17g,%.17g", (**v).x(), (**v).y(), (**v).z());
      row.append(buf, static_cast<std::size_t>(n));
    } else {
      row += ",,,";
    }
  }
  row += "," + std::to_string(m.flags) + ",";
  return row;
}

inline std::vector<std::string> split_lines(const std::string& s) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < s.size()) {
    const auto eol = s.find('\n', start);
    if (eol == std::string::npos) {
      lines.push_back(s.substr(start));
      break;
    }
    lines.push_back(s.substr(start, eol - start));
    start = eol + 1;
  }
  return lines;
}

struct SubRun {
  std::optional<std::uint16_t> port;  // what it said it listens on
  std::optional<int> exit_code;       // nullopt: did not end in time (killed)
  std::string out, err;
};

// Starts a subscriber (argv: the posefair binary or python3 and its arguments; it must
// listen on 127.0.0.1:0 and exit by itself), waits for its "listening on" line, sends the
// scenario to the port it printed, and waits for it to exit.
inline SubRun run_subscriber(const std::vector<std::string>& argv, const Scenario& sc, const TempDir& dir,
                             std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
  SubRun r;
  Subprocess p(argv, dir / "stdout.txt", dir / "stderr.txt");
  r.port = p.wait_for_listening_port(std::chrono::seconds(10));
  if (r.port) send_scenario(sc, *r.port);
  r.exit_code = p.wait(r.port ? timeout : std::chrono::milliseconds(0));
  r.out = p.out();
  r.err = p.err();
  return r;
}

// Whether a stats line ends in ", latency min A µs p50 B µs p99 C µs max D µs" with integers
// A ≤ B ≤ C ≤ D. (No std::regex: GCC 12 warns falsely inside it under ASan.)
inline bool has_latency_tail(const std::string& stats) {
  const auto at = stats.find(", latency min ");
  if (at == std::string::npos) return false;
  long long a = 0, b = 0, c = 0, d = 0;
  int end = -1;
  const std::string tail = stats.substr(at);
  if (std::sscanf(tail.c_str(), ", latency min %lld µs p50 %lld µs p99 %lld µs max %lld µs%n", &a, &b, &c, &d, &end) !=
      4)
    return false;
  return end == static_cast<int>(tail.size()) && a <= b && b <= c && c <= d;
}

inline std::vector<std::string> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < line.size()) {
    const auto j = line.find(' ', i);
    words.push_back(line.substr(i, j == std::string::npos ? std::string::npos : j - i));
    if (j == std::string::npos) break;
    i = j + 1;
  }
  return words;
}

// The stats line from stderr ("" if none).
inline std::string stats_line(const std::string& err) {
  for (const auto& line : split_lines(err))
    if (line.rfind("stats: ", 0) == 0) return line;
  return {};
}

}  // namespace posefair::testing
