// GPIO against the kernel (label hw;gpio: root and gpio-sim, inside the test VM). Each test
// makes its own simulated chip (gpio_sim.hpp) and removes it.
//  1. Edge timestamps are the kernel's CLOCK_MONOTONIC, and samples pushed through the
//     data-ready sink are paired by the rule (paired, missing, extra), counters as it says.
//  2. A line held by another consumer: samples pass unpaired, logged once; released, it is taken.
//  3. The output line toggles once per on_pose() (the sim's value follows), or on its own as a
//     heartbeat.
//  4. End to end: posefaird with a serial stream on a pseudo-terminal and [stream.gpio]; an edge
//     per frame, the published poses carry the edge times, the output line toggles per
//     published pose; the line held by the test at start is taken once released.
#include <gtest/gtest.h>
#include <gpiod.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "../support/daemon_process.hpp"
#include "../support/pseudo_terminal.hpp"
#include "../support/test_files.hpp"
#include "gpio_sim.hpp"
#include "posefair/drivers/gpio_data_ready.hpp"
#include "posefair/drivers/gpio_output_line.hpp"
#include "posefair/drivers/posefair_serial_decoder.hpp"

namespace posefair::testing {
namespace {

using namespace std::chrono_literals;

double now_s() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Collects what the sink forwards.
struct Forwarded final : drivers::SampleSink {
  std::vector<Sample> samples;
  bool push(const Sample& s) override {
    samples.push_back(s);
    return true;
  }
};

// Collects the sink's log lines.
struct LogLines {
  std::mutex m;
  std::vector<std::string> lines;
  drivers::DriverLog log() {
    return [this](drivers::LogLevel, std::string_view s) {
      std::lock_guard lock(m);
      lines.emplace_back(s);
    };
  }
  std::size_t count(const std::string& needle) {
    std::lock_guard lock(m);
    return static_cast<std::size_t>(
        std::count_if(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(needle) != std::string::npos; }));
  }
};

Sample sample_at(double receive_time, std::uint64_t seq) {
  Sample s;
  s.stream_id = 1;
  s.sequence = seq;
  s.receive_time = receive_time;
  s.time = receive_time;
  return s;
}

// The sink requests its line on the first push; waits until the kernel says it is ours.
void take_line(drivers::GpioDataReadySink& sink, drivers::SampleSink& next, const GpioSim& sim, unsigned line) {
  (void)next;
  ASSERT_TRUE(wait_until([&] { return sim.consumer(line) == "posefair-test"; }, 10s)) << "consumer: '" << sim.consumer(line) << "'";
  ASSERT_TRUE(sink.counters().line_held);
}

// A line held by "another program" (the test) until release() or the end of the scope.
class HeldLine {
 public:
  HeldLine(const GpioSim& sim, unsigned offset) {
    chip_ = ::gpiod_chip_open_lookup(sim.chip_name().c_str());
    if (chip_ == nullptr) throw std::runtime_error("cannot open " + sim.chip_name());
    gpiod_line* line = ::gpiod_chip_get_line(chip_, offset);
    if (line == nullptr || ::gpiod_line_request_input(line, "other-program") != 0) {
      release();
      throw std::runtime_error("cannot hold line " + std::to_string(offset));
    }
  }
  ~HeldLine() { release(); }
  HeldLine(const HeldLine&) = delete;
  HeldLine& operator=(const HeldLine&) = delete;
  void release() {
    if (chip_ != nullptr) ::gpiod_chip_close(chip_);  // releases the line
    chip_ = nullptr;
  }

 private:
  gpiod_chip* chip_ = nullptr;
};

// An edge: the pull goes up (rising); [before, after] brackets the kernel's timestamp once the
// event is queued (the sink drains it).
struct Edge {
  double before = 0.0, after = 0.0;
};
Edge rising_edge(const GpioSim& sim, unsigned line, drivers::GpioDataReadySink& sink, std::size_t pending_after) {
  sim.pull(line, false);
  Edge e;
  e.before = now_s();
  sim.pull(line, true);
  const bool queued = wait_until([&] { return sink.take_edges() >= pending_after; }, 10s);
  e.after = now_s();
  EXPECT_TRUE(queued) << "the edge was not seen";
  return e;
}

TEST(GpioDataReady, EdgesCarryMonotonicKernelTimesAndPairWithSamplesByTheRule) {
  GpioSim sim(4, "pf-test-chip");
  Forwarded out;
  LogLines logs;
  drivers::GpioDataReadyOptions o;
  o.chip = sim.chip_name();
  o.line.offset = 1;
  o.edge = drivers::GpioEdge::Rising;
  o.pairing.tolerance_min = 0.0;
  o.pairing.tolerance_max = 5.0;  // the guest is slow: a wide window; the rule, not the width, is tested
  o.consumer = "posefair-test";
  o.log = logs.log();
  drivers::GpioDataReadySink sink(o, out);

  // The first push requests the line; that sample has no edge: missing.
  ASSERT_TRUE(sink.push(sample_at(now_s(), 0)));
  take_line(sink, out, sim, 1);
  EXPECT_EQ(logs.count("took GPIO " + sim.chip_name() + " line 1 (rising)"), 1u);

  // One edge, then a sample: paired, its time the edge's kernel timestamp (CLOCK_MONOTONIC,
  // between the test's monotonic clock before the pull and after the event was queued).
  const Edge e1 = rising_edge(sim, 1, sink, 1);
  const double r1 = now_s();
  ASSERT_TRUE(sink.push(sample_at(r1, 1)));
  ASSERT_EQ(out.samples.size(), 2u);
  EXPECT_GE(out.samples[1].time, e1.before);
  EXPECT_LE(out.samples[1].time, e1.after);
  EXPECT_EQ(out.samples[1].receive_time, r1);

  // No new edge: the next sample is missing and keeps its time.
  const double r2 = now_s();
  ASSERT_TRUE(sink.push(sample_at(r2, 2)));
  EXPECT_EQ(out.samples[2].time, r2);

  // Two edges before one sample: the later one is its edge, the earlier one extra.
  const Edge e2 = rising_edge(sim, 1, sink, 1);
  const Edge e3 = rising_edge(sim, 1, sink, 2);
  ASSERT_TRUE(sink.push(sample_at(now_s(), 3)));
  EXPECT_GE(out.samples[3].time, e3.before);
  EXPECT_LE(out.samples[3].time, e3.after);
  EXPECT_GT(out.samples[3].time, e2.after);

  const drivers::GpioDataReadyCounters c = sink.counters();
  EXPECT_TRUE(c.line_held);
  EXPECT_EQ(c.pairing.edges, 3u);
  EXPECT_EQ(c.pairing.samples, 4u);
  EXPECT_EQ(c.pairing.paired, 2u);
  EXPECT_EQ(c.pairing.missing, 2u);
  EXPECT_EQ(c.pairing.extra_edges, 1u);
  EXPECT_EQ(c.pairing.late_edges, 0u);
  EXPECT_EQ(c.pairing.overflow, 0u);
  EXPECT_EQ(c.request_failures, 0u);
  EXPECT_EQ(c.losses, 0u);
  // A falling edge (the pull going down) is not the configured edge: nothing queued.
  sim.pull(1, false);
  EXPECT_EQ(sink.take_edges(), 0u);
}

TEST(GpioDataReady, ALineHeldByAnotherConsumerIsTakenOnceReleased) {
  GpioSim sim(4, "pf-test-busy");
  // The test holds line 2 as another program would.
  HeldLine held(sim, 2);

  Forwarded out;
  LogLines logs;
  drivers::GpioDataReadyOptions o;
  o.chip = sim.chip_name();
  o.line.offset = 2;
  o.consumer = "posefair-test";
  o.reconnect_min = 0.02;
  o.reconnect_max = 0.1;
  o.log = logs.log();
  drivers::GpioDataReadySink sink(o, out);

  // Samples pass unpaired with their own times while the line is busy; the reason is logged once.
  for (std::uint64_t i = 0; i < 5; ++i) {
    const double r = now_s();
    ASSERT_TRUE(sink.push(sample_at(r, i)));
    EXPECT_EQ(out.samples.back().time, r);
    std::this_thread::sleep_for(30ms);  // paces the pushes past the backoff, waits for nothing
  }
  EXPECT_FALSE(sink.counters().line_held);
  EXPECT_GE(sink.counters().request_failures, 2u);
  EXPECT_EQ(logs.count("(held by 'other-program'); samples pass unpaired, retrying with backoff"), 1u);
  EXPECT_EQ(sink.counters().pairing.samples, 0u);  // unpaired: no sample counted missing either

  // Released: a later push takes it.
  held.release();
  std::uint64_t seq = 5;
  ASSERT_TRUE(wait_until([&] {
    sink.push(sample_at(now_s(), seq++));
    return sink.counters().line_held;
  }, 10s));
  EXPECT_EQ(sim.consumer(2), "posefair-test");
  EXPECT_EQ(logs.count("took GPIO"), 1u);
}

TEST(GpioOutput, TheLineTogglesOncePerPose) {
  GpioSim sim(4, "pf-test-out");
  drivers::GpioOutputOptions o;
  o.chip = "pf-test-out";  // by label
  o.line.offset = 3;
  o.consumer = "posefair-test";
  drivers::GpioOutputLine out(o);
  out.start();
  ASSERT_TRUE(wait_until([&] { return out.counters().line_held; }, 10s));
  EXPECT_EQ(sim.consumer(3), "posefair-test");
  EXPECT_EQ(sim.value(3), 0);
  for (int i = 1; i <= 5; ++i) {
    out.on_pose();
    EXPECT_EQ(sim.value(3), i % 2) << "after pose " << i;
  }
  EXPECT_EQ(out.counters().toggles, 5u);
  EXPECT_EQ(out.counters().errors, 0u);
  out.stop();
  EXPECT_EQ(sim.consumer(3), "");
}

TEST(GpioOutput, AHeartbeatTogglesOnItsOwn) {
  GpioSim sim(2, "pf-test-beat");
  drivers::GpioOutputOptions o;
  o.chip = sim.chip_name();
  o.line.offset = 1;
  o.mode = drivers::GpioOutputMode::Heartbeat;
  o.heartbeat_hz = 20.0;
  o.consumer = "posefair-test";
  drivers::GpioOutputLine out(o);
  out.start();
  // The line is seen high and low on the chip, without a single pose.
  bool high = false, low = false;
  ASSERT_TRUE(wait_until([&] {
    (sim.value(1) != 0 ? high : low) = true;
    return high && low && out.counters().toggles >= 4;
  }, 10s)) << "toggles " << out.counters().toggles;
  out.stop();
  EXPECT_EQ(out.counters().errors, 0u);
  EXPECT_EQ(sim.consumer(1), "");
}

TEST(GpioDaemon, EdgesTimeTheStreamsPosesAndTheOutputTogglesPerPublishedPose) {
  GpioSim sim(4, "pf-test-daemon", {"DRDY", "", "SCOPE"});
  ScratchDir dir("posefair-gpio-");
  Collector poses;
  PseudoTerminal pty;
  // The test holds the data-ready line first: the daemon runs unpaired until it is released.
  HeldLine held(sim, 0);

  const fs::path config = dir / "posefaird.toml";
  write_text(config, "[logging]\nstatus_interval = 0\n\n[[stream]]\nid = 1\nname = \"imu\"\n"
                     "driver = { type = \"serial\", device = \"" + pty.slave() +
                     "\", protocol = \"posefair\", time_source = \"receive\" }\n"
                     "[stream.gpio]\nchip = \"pf-test-daemon\"\ndata_ready_line = \"DRDY\"\n"
                     "tolerance_max = 0.15\noutput_line = \"SCOPE\"\n\n"
                     "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(poses.port()) + "\"]\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  // Bounds are generous: the guest is slow, more so on a loaded host (a daemon start took >10 s once).
  ASSERT_TRUE(wait_for_log_or_exit(d, "took GPIO output pf-test-daemon line 'SCOPE'", 60s)) << d.err();

  std::uint32_t device_us = 0;
  auto frame = [&] {
    const std::vector<std::uint8_t> f = drivers::encode_posefair_frame(device_us += 200000, Quat::Identity(), nullptr);
    pty.write(std::string_view(reinterpret_cast<const char*>(f.data()), f.size()));
  };
  // Busy: frames keep coming (every 50 ms, the daemon retries on them) until the failure is logged.
  ASSERT_TRUE(wait_until([&] {
    frame();
    std::this_thread::sleep_for(50ms);
    return d.err().find("(held by 'other-program')") != std::string::npos || !d.running();
  }, 30s)) << d.err();
  held.release();
  ASSERT_TRUE(wait_until([&] {
    frame();
    std::this_thread::sleep_for(50ms);
    return d.err().find("took GPIO pf-test-daemon line 'DRDY' (rising)") != std::string::npos || !d.running();
  }, 30s)) << d.err();
  EXPECT_EQ(count_of(d.err(), "cannot request"), 1u) << d.err();
  ASSERT_TRUE(wait_until([&] { return sim.consumer(0) == "posefaird:imu"; }, 5s));
  const std::size_t before = poses.all().size();

  // Now an edge per frame: pull up (the kernel timestamps it), then the frame's bytes.
  std::vector<Edge> edges;
  for (int i = 0; i < 20; ++i) {
    sim.pull(0, false);
    Edge e;
    e.before = now_s();
    sim.pull(0, true);
    e.after = now_s();
    // A device's bytes follow its data-ready edge by their transfer time (a posefair frame at
    // 115200 baud: about 3 ms). The kernel stamps the edge in the interrupt but queues the event
    // from the interrupt's thread; bytes written at once could be read by the daemon on the
    // guest's other CPU before that thread has run. 30 ms stands for the transfer time with room
    // for the emulated guest, and keeps unpaired samples (their receive times) out of the edge
    // windows checked below.
    std::this_thread::sleep_for(30ms);
    frame();
    edges.push_back(e);
    std::this_thread::sleep_for(200ms);  // the frame rate (5 Hz): a period longer than the window
  }
  // The engine's lag is 0: a pose per frame.
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= before + 20 || !d.running(); }, 30s)) << d.err();
  const std::vector<Collector::Got> got = poses.all();
  std::size_t in_edge_time = 0;
  for (std::size_t i = before; i < got.size(); ++i) {
    const double t = got[i].m.sample_time;
    if (std::any_of(edges.begin(), edges.end(), [&](const Edge& e) { return t >= e.before && t <= e.after + 0.002; }))
      ++in_edge_time;
  }
  // The first pose after the switch may be the last unpaired sample's.
  EXPECT_GE(in_edge_time, got.size() - before - 1) << "of " << got.size() - before;

  d.send_signal(SIGUSR1);
  ASSERT_TRUE(wait_for_log_or_exit(d, "; gpio output held, toggles ", 20s)) << d.err();
  const std::string log = d.err();
  const auto published = last_counters(log, "imu", 1);
  ASSERT_TRUE(published.has_value()) << log;
  const std::string toggles_at = "; gpio output held, toggles " + std::to_string(published->published) + ", errors 0";
  EXPECT_NE(log.find(toggles_at), std::string::npos) << log;
  EXPECT_EQ(sim.value(2), static_cast<int>(published->published % 2));
  EXPECT_NE(log.find("; gpio data-ready held, edges 20, paired 20, missing "), std::string::npos) << log;
  d.send_signal(SIGTERM);
  EXPECT_EQ(d.wait(30s), 0) << d.err();
  EXPECT_EQ(sim.consumer(0), "");
}

}  // namespace
}  // namespace posefair::testing
