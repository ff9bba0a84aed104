#pragma once
// Running posefaird and posefair as child processes in a test: paths of the built binaries,
// bounded waits on a child's log, the daemon's counter lines parsed, and a UDP collector of
// every datagram on 127.0.0.1. Shared by the end-to-end tests (tests/daemon) and the kernel
// interface tests inside the VM (tests/hw).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "../protocol/subprocess.hpp"
#include "test_files.hpp"
#include "udp_collector.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::testing {

inline const std::string kPosefaird = POSEFAIR_BINARY_DIR "/daemon/posefaird";
inline const std::string kPosefair = POSEFAIR_CLI_PROGRAM;

namespace daemon_process_detail {
namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
}  // namespace daemon_process_detail
using namespace daemon_process_detail;

inline std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string cur;
  std::istringstream in(text);
  while (std::getline(in, cur, sep)) parts.push_back(cur);
  return parts;
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  for (std::string& l : split(text, '\n'))
    if (!l.empty()) out.push_back(std::move(l));
  return out;
}

inline std::size_t count_of(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) ++n;
  return n;
}

// strtod is correctly rounded: the shortest / %.17g text of a double reads back as that double.
inline double to_double(const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size()) throw std::runtime_error("not a number: '" + s + "'");
  return v;
}

inline std::uint64_t to_u64(const std::string& s) { return std::stoull(s); }

// Waits (bounded) until a child's stderr holds `needle` `occurrences` times; false on timeout
// or as soon as the child has exited without it.
inline bool wait_for_log_or_exit(Subprocess& p, const std::string& needle, std::chrono::milliseconds timeout,
                                 std::size_t occurrences = 1) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    const bool alive = p.running();  // first: if it had exited, the log read next is complete
    if (count_of(p.err(), needle) >= occurrences) return true;
    if (!alive || Clock::now() > deadline) return false;
    std::this_thread::sleep_for(10ms);
  }
}

// The daemon's counter line for one stream ("stream NAME (id N, ...): received N, dropped N
// (ring N, publish N), rejected N, out-of-order N, emitted N, clamped N, restarts N,
// published N, send failures N, recorded N (dropped N), latency ..."); the last one in the log.
struct Counters {
  std::string line;
  std::uint64_t received = 0, dropped = 0, ring = 0, publish = 0, rejected = 0, out_of_order = 0, emitted = 0,
                published = 0, send_failures = 0, recorded = 0, record_dropped = 0;
};

inline std::optional<Counters> last_counters(const std::string& log, const std::string& name, std::uint32_t id) {
  const std::string head = "stream " + name + " (id " + std::to_string(id) + ", ";
  std::optional<Counters> found;
  for (const std::string& line : lines_of(log)) {
    const auto at = line.find(head);
    if (at == std::string::npos) continue;
    const auto body_at = line.find("): received ", at);
    if (body_at == std::string::npos) continue;
    const std::string body = line.substr(body_at + 2);  // "received N, dropped ..."
    auto field = [&body](const std::string& label) -> std::uint64_t {
      const auto p = body.find(label);
      if (p == std::string::npos) throw std::runtime_error("no '" + label + "' in " + body);
      return std::stoull(body.substr(p + label.size()));
    };
    Counters c;
    c.line = line;
    c.received = field("received ");
    c.dropped = field(", dropped ");
    c.ring = field("(ring ");
    c.publish = field(", publish ");
    c.rejected = field(", rejected ");
    c.out_of_order = field(", out-of-order ");
    c.emitted = field(", emitted ");
    c.published = field(", published ");
    c.send_failures = field(", send failures ");
    c.recorded = field(", recorded ");
    c.record_dropped = field("(dropped ");
    found = c;
  }
  return found;
}

// Asks the daemon for its counter lines (SIGUSR1) until the stream's line says it received at
// least `at_least` samples: a test that waits for most of the poses to arrive, not all, may ask
// while the last few are still on their way through the kernel (a reader scheduled late). The
// last line read in any case; nothing if the daemon wrote none before the timeout.
inline std::optional<Counters> counters_once_received(Subprocess& p, const std::string& name, std::uint32_t id,
                                                      std::uint64_t at_least, std::chrono::milliseconds timeout) {
  const std::string head = "stream " + name + " (id " + std::to_string(id) + ", ";
  const auto deadline = Clock::now() + timeout;
  std::optional<Counters> c;
  do {
    const std::size_t lines = count_of(p.err(), head);
    p.send_signal(SIGUSR1);
    if (!wait_for_log_or_exit(p, head, 2s, lines + 1)) break;
    c = last_counters(p.err(), name, id);
    if (c && c->received >= at_least) break;
    std::this_thread::sleep_for(100ms);
  } while (Clock::now() < deadline);
  return c;
}

inline std::vector<std::string> daemon_args(const fs::path& config) {
  return {kPosefaird, "-c", config.string(), "--log-target", "stderr"};
}

// Every datagram reaching a socket bound to 127.0.0.1:0, received on a thread of its own.
using Collector = UdpCollector;

}  // namespace posefair::testing
