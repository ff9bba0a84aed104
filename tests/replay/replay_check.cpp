// The golden replay check (tests/replay/README.md), the gpsd way: a replay log's bytes go
// through a pseudo-terminal into the real SerialDriver, with the decoder the log's header
// names, and what comes out (every sample, then the decoder's counters) must equal the log's
// .chk file line for line.
//
//   replay_check <device>.log               compare with <device>.log.chk; exit 0 or 1
//   replay_check --regenerate <device>.log  write <device>.log.chk from this run
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../support/pseudo_terminal.hpp"
#include "posefair/drivers/serial_driver.hpp"
#include "replay_log.hpp"

namespace {

using namespace std::chrono_literals;
namespace drv = posefair::drivers;

class CollectingSink final : public drv::SampleSink {
 public:
  bool push(const posefair::Sample& s) override {
    std::lock_guard lock(mutex_);
    samples_.push_back(s);
    return true;
  }
  std::vector<posefair::Sample> samples() const {
    std::lock_guard lock(mutex_);
    return samples_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<posefair::Sample> samples_;
};

// Everything the driver made of the log, as the .chk text. Receive times are left out (they
// are this run's clock); device times are in, as the decoder unwrapped them.
std::string render(const std::string& log_name, const std::string& protocol, const std::vector<posefair::Sample>& samples,
                   const drv::DecoderCounters& c) {
  std::string out = "# " + log_name + " through a pseudo-terminal into SerialDriver, protocol " + protocol + "\n";
  out += "# sequence device_time_s qw qx qy qz [px py pz] [g gx gy gz] [a ax ay az] [m mx my mz]\n";
  char buf[256];
  for (const posefair::Sample& s : samples) {
    const posefair::Quat& q = s.orientation;
    std::string device_time = "-";
    if (s.flags & posefair::kHasDeviceTime) {
      std::snprintf(buf, sizeof buf, "%.6f", s.device_time);
      device_time = buf;
    }
    if (s.has_orientation())
      std::snprintf(buf, sizeof buf, "%" PRIu64 " %s %.8f %.8f %.8f %.8f", s.sequence, device_time.c_str(), q.w(),
                    q.x(), q.y(), q.z());
    else  // a raw-only sample: its quaternion is not a measurement
      std::snprintf(buf, sizeof buf, "%" PRIu64 " %s - - - -", s.sequence, device_time.c_str());
    out += buf;
    const auto vector = [&](const char* tag, const posefair::Vec3& v) {
      std::snprintf(buf, sizeof buf, "%s%.6f %.6f %.6f", tag, v.x(), v.y(), v.z());
      out += buf;
    };
    if (s.has_position()) vector(" ", s.position);
    if (s.has_gyro()) vector(" g ", s.gyro);
    if (s.has_accel()) vector(" a ", s.accel);
    if (s.has_mag()) vector(" m ", s.mag);
    out += "\n";
  }
  std::snprintf(buf, sizeof buf,
                "# counters: bytes %" PRIu64 " frames %" PRIu64 " samples %" PRIu64 " bad_checksum %" PRIu64
                " malformed %" PRIu64 " ignored_frames %" PRIu64 " resyncs %" PRIu64 " skipped_bytes %" PRIu64 "\n",
                c.bytes, c.frames, c.samples, c.bad_checksum, c.malformed, c.ignored_frames, c.resyncs, c.skipped_bytes);
  out += buf;
  return out;
}

std::string run_through_pty(const posefair::replay::ReplayLog& log, drv::DecoderCounters& counters,
                            std::vector<posefair::Sample>& samples) {
  posefair::testing::PseudoTerminal pty;
  drv::SerialDriverOptions o;
  o.port.device = pty.slave();
  o.settings.baud = std::stoi(log.header.at("baud"));
  o.protocol = log.header.at("protocol");
  // "# option.<key>: <value>" lines: the decoder's options, as a config's string values.
  for (const auto& [key, value] : log.header)
    if (key.rfind("option.", 0) == 0) o.decoder_options[key.substr(7)] = value;
  o.reconnect_min = 0.01;
  o.reconnect_max = 0.05;
  drv::SerialDriver driver(std::move(o));
  CollectingSink sink;
  std::jthread thread([&](std::stop_token stop) { driver.run(stop, sink); });

  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!driver.connected()) {
    if (std::chrono::steady_clock::now() > deadline) return "the driver never opened the pseudo-terminal";
    std::this_thread::sleep_for(1ms);
  }
  // Chunks of 1..300 bytes, as reads from a USB-serial adapter come: the output must not
  // depend on where the reads split the stream.
  std::mt19937 rng(7);
  for (std::size_t at = 0; at < log.data.size();) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 300, log.data.size() - at);
    pty.write(std::string_view(log.data).substr(at, n));
    at += n;
  }
  while (driver.decoder_counters().bytes < log.data.size()) {
    if (std::chrono::steady_clock::now() > deadline)
      return "the decoder saw " + std::to_string(driver.decoder_counters().bytes) + " of " +
             std::to_string(log.data.size()) + " bytes";
    std::this_thread::sleep_for(1ms);
  }
  thread.request_stop();
  thread.join();
  if (driver.outages() != 0) return "the pseudo-terminal was lost during the replay";
  counters = driver.decoder_counters();
  samples = sink.samples();
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  const bool regenerate = argc == 3 && std::string(argv[1]) == "--regenerate";
  if (!(argc == 2 || regenerate)) {
    std::cerr << "usage: replay_check [--regenerate] <device>.log\n";
    return 64;
  }
  const std::string log_path = argv[argc - 1];
  const std::string chk_path = log_path + ".chk";
  try {
    const posefair::replay::ReplayLog log = posefair::replay::read_replay_log(log_path);
    drv::DecoderCounters counters;
    std::vector<posefair::Sample> samples;
    if (const std::string problem = run_through_pty(log, counters, samples); !problem.empty()) {
      std::cerr << log_path << ": " << problem << "\n";
      return 1;
    }
    const std::string name = log_path.substr(log_path.find_last_of('/') + 1);
    const std::string got = render(name, log.header.at("protocol"), samples, counters);
    if (regenerate) {
      std::ofstream(chk_path, std::ios::binary) << got;
      std::cout << chk_path << ": " << samples.size() << " samples written\n";
      return 0;
    }
    std::ifstream in(chk_path, std::ios::binary);
    if (!in) {
      std::cerr << chk_path << ": missing (make it with replay_check --regenerate and explain it in the commit)\n";
      return 1;
    }
    const std::string want((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (got == want) {
      std::cout << name << ": " << samples.size() << " samples and the counters as in " << chk_path << "\n";
      return 0;
    }
    // Like diff: the first lines that differ, with their line numbers.
    std::istringstream a(want), b(got);
    std::string la, lb;
    int line = 0, shown = 0;
    while (shown < 10) {
      ++line;
      const bool ma = static_cast<bool>(std::getline(a, la));
      const bool mb = static_cast<bool>(std::getline(b, lb));
      if (!ma && !mb) break;
      if (ma && mb && la == lb) continue;
      std::cerr << chk_path << ":" << line << ":\n  expected: " << (ma ? la : "<end>") << "\n  got:      " << (mb ? lb : "<end>")
                << "\n";
      ++shown;
    }
    std::cerr << name << ": the decoded output differs from " << chk_path << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << log_path << ": " << e.what() << "\n";
    return 1;
  }
}
