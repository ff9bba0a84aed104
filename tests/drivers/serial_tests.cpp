// The serial transport on pseudo-terminals: SerialPort (open by path through a symlink, reads
// with timeouts, "device gone" when the other side hangs up) and SerialDriver (samples with
// receive times, sequence numbers and counters; chunked writes; prompt stops; unplug and replug;
// a device that appears late), with a line-protocol decoder defined here.
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../support/pseudo_terminal.hpp"
#include "../support/test_files.hpp"
#include "posefair/drivers/serial_driver.hpp"
#include "posefair/drivers/serial_port.hpp"

namespace posefair::drivers {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double monotonic_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Waits up to `limit` for `done`, polling every millisecond.
bool eventually(const std::function<bool()>& done, std::chrono::milliseconds limit = 3000ms) {
  const Clock::time_point end = Clock::now() + limit;
  while (Clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return done();
}

using Pty = testing::PseudoTerminal;

// Points `link` at `target`, atomically replacing what it pointed at (as udev re-points
// /dev/serial/by-id links on a replug).
void point_link(const std::filesystem::path& link, const std::string& target) {
  const std::filesystem::path fresh = link.string() + ".new";
  std::filesystem::remove(fresh);
  std::filesystem::create_symlink(target, fresh);
  std::filesystem::rename(fresh, link);
}

// "Q w x y z [device_time]\n" per sample; any other line is malformed.
class LineDecoder final : public Decoder {
 public:
  std::string_view protocol() const override { return "test-lines"; }
  void feed(std::span<const std::uint8_t> bytes, DecodedSink& sink) override {
    counters_.bytes += bytes.size();
    for (const std::uint8_t b : bytes) {
      if (b != '\n') {
        if (line_.size() < 256) line_.push_back(static_cast<char>(b));
        continue;
      }
      DecodedSample d;
      double w = 0, x = 0, y = 0, z = 0, t = 0;
      const int n = std::sscanf(line_.c_str(), "Q %lf %lf %lf %lf %lf", &w, &x, &y, &z, &t);
      line_.clear();
      if (n != 4 && n != 5) {
        ++counters_.malformed;
        continue;
      }
      ++counters_.frames;
      d.orientation = Quat(w, x, y, z);
      if (n == 5) {
        d.flags |= kHasDeviceTime;
        d.device_time = t;
      }
      ++counters_.samples;
      sink.on_sample(d);
    }
  }
  void reset() override {
    line_.clear();
    ++resets;
  }
  std::atomic<int> resets{0};

 private:
  std::string line_;
};

std::string line(double w, double x, double y, double z) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "Q %.6f %.6f %.6f %.6f\n", w, x, y, z);
  return buf;
}

std::string line(double w, double x, double y, double z, double t) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "Q %.6f %.6f %.6f %.6f %.6f\n", w, x, y, z, t);
  return buf;
}

class CollectingSink final : public SampleSink {
 public:
  bool push(const Sample& s) override {
    std::lock_guard lock(mutex_);
    samples_.push_back(s);
    return true;
  }
  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return samples_.size();
  }
  std::vector<Sample> samples() const {
    std::lock_guard lock(mutex_);
    return samples_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Sample> samples_;
};

struct LogLine {
  LogLevel level;
  std::string text;
};

class LogCapture {
 public:
  DriverLog sink() {
    return [this](LogLevel level, std::string_view text) {
      std::lock_guard lock(mutex_);
      lines_.push_back(LogLine{level, std::string(text)});
    };
  }
  std::vector<LogLine> lines() const {
    std::lock_guard lock(mutex_);
    return lines_;
  }
  std::size_t count(std::string_view needle) const {
    std::lock_guard lock(mutex_);
    std::size_t n = 0;
    for (const LogLine& l : lines_)
      if (l.text.find(needle) != std::string::npos) ++n;
    return n;
  }
  std::string all() const {
    std::lock_guard lock(mutex_);
    std::string s;
    for (const LogLine& l : lines_) s += l.text + "\n";
    return s;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<LogLine> lines_;
};

// How soon a stop must return: the driver looks at its stop token after every read (20 ms
// timeout) and inside every backoff wait, so it returns in about 20 ms; the rest is slack for a
// sanitizer build on a loaded 2-core machine, where a join once took 121 ms. A stop that slept
// through a backoff of 0.5 s, or waited in a read without a timeout, still fails.
constexpr std::chrono::milliseconds kPromptStop{250};

// A driver on its own thread, stopped and joined at the end.
class Running {
 public:
  Running(SerialDriver& driver, SampleSink& sink)
      : thread_([&driver, &sink](std::stop_token stop) { driver.run(stop, sink); }) {}
  // Requests a stop and returns how long the join took.
  std::chrono::milliseconds stop() {
    const Clock::time_point t0 = Clock::now();
    thread_.request_stop();
    if (thread_.joinable()) thread_.join();
    return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0);
  }

 private:
  std::jthread thread_;
};

struct Fixture {
  testing::ScratchDir dir{"posefair-serial-"};
  std::filesystem::path link = dir / "tracker";
  LogCapture log;
  LineDecoder* decoder = nullptr;  // owned by the driver

  SerialDriverOptions options(double reconnect_min = 0.02, double reconnect_max = 0.2) {
    SerialDriverOptions o;
    o.port.device = link.string();
    auto d = std::make_unique<LineDecoder>();
    decoder = d.get();
    o.decoder = std::move(d);
    o.stream_id = 17;
    o.reconnect_min = reconnect_min;
    o.reconnect_max = reconnect_max;
    o.log = log.sink();
    return o;
  }
};

// --- SerialPort ---

TEST(SerialPort, ReadsWithATimeoutAndReportsAHangupAsDeviceGone) {
  Pty pty;
  testing::ScratchDir dir("posefair-serial-");
  const std::filesystem::path link = dir / "imu";
  point_link(link, pty.slave());
  SerialPort port;
  SerialPortSpec spec;
  spec.device = link.string();
  SerialSettings settings;
  settings.baud = 921600;
  ASSERT_FALSE(port.open(spec, settings)) << port.path();
  EXPECT_TRUE(port.is_open());
  EXPECT_EQ(port.path(), std::filesystem::canonical(pty.slave()).string());  // the link is resolved

  std::uint8_t buf[64];
  const Clock::time_point t0 = Clock::now();
  SerialPort::ReadResult r = port.read(buf, 30);
  EXPECT_EQ(r.bytes, 0u);
  EXPECT_FALSE(r.error);
  EXPECT_GE(Clock::now() - t0, 25ms);

  pty.write("hello");
  r = port.read(buf, 1000);
  ASSERT_FALSE(r.error) << r.error.message;
  ASSERT_EQ(r.bytes, 5u);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(buf), 5), "hello");

  // Writing to the device works too.
  const std::uint8_t ping[] = {'p', 'i', 'n', 'g'};
  EXPECT_FALSE(port.write(ping, 100));

  pty.close();
  r = port.read(buf, 1000);
  EXPECT_EQ(r.error.kind, SerialErrorKind::DeviceGone) << r.error.message;
  port.close();
  EXPECT_FALSE(port.is_open());
}

TEST(SerialPort, OpenTellsAbsentFromRefused) {
  testing::ScratchDir dir("posefair-serial-");
  SerialPort port;
  SerialPortSpec spec;
  spec.device = (dir / "nothing-here").string();
  SerialError e = port.open(spec, SerialSettings{});
  EXPECT_EQ(e.kind, SerialErrorKind::NotFound) << e.message;
  EXPECT_NE(e.message.find("nothing-here"), std::string::npos) << e.message;

  // A dangling link (an unplugged device's by-id link) is absent too.
  std::filesystem::create_symlink(dir / "gone", dir / "dangling");
  spec.device = (dir / "dangling").string();
  EXPECT_EQ(port.open(spec, SerialSettings{}).kind, SerialErrorKind::NotFound);

  // A regular file is not a terminal.
  { std::FILE* f = std::fopen((dir / "file").c_str(), "w"); std::fclose(f); }
  spec.device = (dir / "file").string();
  EXPECT_EQ(port.open(spec, SerialSettings{}).kind, SerialErrorKind::NotATerminal);

  // A non-standard rate on a pseudo-terminal, bad data bits: settings refused.
  Pty pty;
  spec.device = pty.slave();
  SerialSettings odd;
  odd.baud = 123457;
  EXPECT_EQ(port.open(spec, odd).kind, SerialErrorKind::BadSettings);
  SerialSettings nine;
  nine.data_bits = 9;
  EXPECT_EQ(port.open(spec, nine).kind, SerialErrorKind::BadSettings);
  EXPECT_FALSE(port.is_open());

  // Every parity, stop bits and flow control that termios has.
  for (const Parity p : {Parity::None, Parity::Odd, Parity::Even, Parity::Mark, Parity::Space}) {
    SerialSettings s;
    s.parity = p;
    s.data_bits = 7;
    s.stop_bits = 2;
    s.flow_control = FlowControl::RtsCts;
    const SerialError e = port.open(spec, s);
    EXPECT_FALSE(e) << describe(s) << ": " << e.message;
  }
  // The port is held exclusively: a second open is refused as busy.
  SerialPort second;
  const SerialError busy = second.open(spec, SerialSettings{});
  if (::geteuid() != 0) {
    EXPECT_EQ(busy.kind, SerialErrorKind::Busy) << busy.message;  // root ignores TIOCEXCL
  }
  // Closed, it is free again (a pty slave keeps TIOCEXCL past its close unless it is undone).
  port.close();
  second.close();
  const SerialError reopened = second.open(spec, SerialSettings{});
  EXPECT_FALSE(reopened) << reopened.message;
}

TEST(SerialPort, AnAbsentUsbIdIsNotFound) {
  SerialPort port;
  SerialPortSpec spec;
  spec.usb = UsbId{0xffff, 0xfffe};
  spec.usb_serial = "NOPE";
  const SerialError e = port.open(spec, SerialSettings{});
  EXPECT_EQ(e.kind, SerialErrorKind::NotFound);
  EXPECT_NE(e.message.find("usb ffff:fffe serial NOPE"), std::string::npos) << e.message;
}

TEST(SerialPort, UsbIdsSettingsAndListing) {
  EXPECT_EQ(parse_usb_id("1a86:7523"), (UsbId{0x1a86, 0x7523}));
  EXPECT_EQ(parse_usb_id("10C4:EA60"), (UsbId{0x10c4, 0xea60}));
  EXPECT_EQ(parse_usb_id("403:6001"), (UsbId{0x0403, 0x6001}));
  for (const char* bad : {"", "1a86", "1a86:", ":7523", "1a86:75231", "1a86-7523", "xyz:0001", "1a86:7523:1"})
    EXPECT_EQ(parse_usb_id(bad), std::nullopt) << bad;
  EXPECT_EQ(to_string(UsbId{0x0403, 0x6001}), "0403:6001");

  SerialSettings s;
  EXPECT_EQ(describe(s), "115200 8N1");
  s.baud = 9600;
  s.data_bits = 7;
  s.parity = Parity::Even;
  s.stop_bits = 2;
  s.flow_control = FlowControl::RtsCts;
  EXPECT_EQ(describe(s), "9600 7E2 rtscts");
  s.baud = 0;
  EXPECT_THROW(validate(s), std::invalid_argument);

  // Whatever this machine has; the call itself must work.
  const std::vector<PortInfo> ports = list_serial_ports();
  for (std::size_t i = 1; i < ports.size(); ++i) EXPECT_LT(ports[i - 1].path, ports[i].path);
  for (const PortInfo& p : ports) EXPECT_FALSE(p.path.empty());
}

// --- SerialDriver ---

TEST(SerialDriver, SamplesArriveWithReceiveTimesSequenceNumbersAndCounters) {
  Fixture f;
  Pty pty;
  point_link(f.link, pty.slave());
  SerialDriver driver(f.options());
  EXPECT_EQ(driver.name(), "serial:" + f.link.string());
  EXPECT_EQ(driver.protocol(), "test-lines");
  CollectingSink sink;
  Running run(driver, sink);
  ASSERT_TRUE(eventually([&] { return driver.connected(); }));
  EXPECT_EQ(driver.device_path(), std::filesystem::canonical(pty.slave()).string());

  std::string text;
  for (int i = 0; i < 10; ++i) text += line(1, 0, 0, 0.001 * i, 0.01 * i);
  text += "garbage\n";
  const double before = monotonic_seconds();
  pty.write(text);
  ASSERT_TRUE(eventually([&] { return sink.size() >= 10 && driver.decoder_counters().malformed == 1; }));
  const double after = monotonic_seconds();

  const std::vector<Sample> got = sink.samples();
  ASSERT_EQ(got.size(), 10u);
  for (std::size_t i = 0; i < got.size(); ++i) {
    const Sample& s = got[i];
    EXPECT_EQ(s.stream_id, 17u);
    EXPECT_EQ(s.sequence, i);
    EXPECT_GE(s.receive_time, before);
    EXPECT_LE(s.receive_time, after);
    EXPECT_TRUE((s.flags & kHasDeviceTime) != 0);
    EXPECT_DOUBLE_EQ(s.device_time, 0.01 * static_cast<double>(i));
    EXPECT_NEAR(s.orientation.z(), 0.001 * static_cast<double>(i), 1e-9);
    // Not yet trusted: the receive time (samples of one read kept 1 µs apart).
    EXPECT_NEAR(s.time, s.receive_time, 1e-4);
    if (i > 0) {
      EXPECT_GT(s.time, got[i - 1].time);
      EXPECT_GE(s.receive_time, got[i - 1].receive_time);
    }
  }
  EXPECT_EQ(driver.bytes(), text.size());
  EXPECT_EQ(driver.samples(), 10u);
  EXPECT_EQ(driver.dropped(), 0u);
  EXPECT_EQ(driver.outages(), 0u);
  EXPECT_EQ(driver.reconnects(), 0u);
  const DecoderCounters c = driver.decoder_counters();
  EXPECT_EQ(c.frames, 10u);
  EXPECT_EQ(c.samples, 10u);
  EXPECT_EQ(c.bytes, text.size());
  EXPECT_FALSE(driver.device_time_trusted());
  EXPECT_EQ(driver.time_base_counters().receive_samples, 10u);
  EXPECT_LT(run.stop(), kPromptStop);
  EXPECT_FALSE(driver.connected());

  const std::vector<LogLine> lines = f.log.lines();
  ASSERT_EQ(lines.size(), 1u) << f.log.all();
  EXPECT_EQ(lines[0].level, LogLevel::Info);
  EXPECT_NE(lines[0].text.find("opened " + f.link.string() + " -> "), std::string::npos) << lines[0].text;
  EXPECT_NE(lines[0].text.find("115200 8N1, protocol test-lines"), std::string::npos) << lines[0].text;
}

TEST(SerialDriver, ChunkedWritesGiveTheSameSamplesEachStampedAfterItsLastByte) {
  Fixture f;
  Pty pty;
  point_link(f.link, pty.slave());
  SerialDriver driver(f.options());
  CollectingSink sink;
  Running run(driver, sink);
  ASSERT_TRUE(eventually([&] { return driver.connected(); }));

  constexpr int kSamples = 60;
  std::string text;
  std::vector<std::size_t> frame_end;  // offset just past each frame
  for (int i = 0; i < kSamples; ++i) {
    text += line(std::cos(0.01 * i), std::sin(0.01 * i), 0, 0);
    frame_end.push_back(text.size());
  }
  // Chunks of 1..23 bytes, a pause after some; remember when each byte went out.
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::size_t> size(1, 23);
  std::vector<double> sent_at(text.size());
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t n = std::min(size(rng), text.size() - at);
    const double t = monotonic_seconds();
    for (std::size_t k = at; k < at + n; ++k) sent_at[k] = t;
    pty.write(std::string_view(text).substr(at, n));
    at += n;
    if (rng() % 3 == 0) std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(eventually([&] { return sink.size() >= kSamples; }));
  const std::vector<Sample> got = sink.samples();
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kSamples));
  for (int i = 0; i < kSamples; ++i) {
    const Sample& s = got[static_cast<std::size_t>(i)];
    EXPECT_EQ(s.sequence, static_cast<std::uint64_t>(i));
    EXPECT_NEAR(s.orientation.w(), std::cos(0.01 * i), 1e-6);
    EXPECT_NEAR(s.orientation.x(), std::sin(0.01 * i), 1e-6);
    EXPECT_EQ(s.flags, 0u);
    // Stamped after the read that completed the frame, so after its last byte was written.
    EXPECT_GE(s.receive_time, sent_at[frame_end[static_cast<std::size_t>(i)] - 1]);
    EXPECT_GE(s.time, s.receive_time);  // the receive time, nudged 1 µs apart within a read
    EXPECT_LT(s.time, s.receive_time + 1e-4);
  }
  EXPECT_EQ(driver.bytes(), text.size());
  EXPECT_EQ(driver.decoder_counters().malformed, 0u);
  EXPECT_LT(run.stop(), kPromptStop);
}

TEST(SerialDriver, AStopReturnsPromptlyWhileWaitingForDataOrForTheDevice) {
  {
    Fixture f;
    Pty pty;
    point_link(f.link, pty.slave());
    SerialDriver driver(f.options());
    CollectingSink sink;
    Running run(driver, sink);
    ASSERT_TRUE(eventually([&] { return driver.connected(); }));
    std::this_thread::sleep_for(30ms);
    EXPECT_LT(run.stop(), kPromptStop);
  }
  {
    Fixture f;  // no device at all, long backoff
    SerialDriver driver(f.options(0.5, 5.0));
    CollectingSink sink;
    Running run(driver, sink);
    ASSERT_TRUE(eventually([&] { return driver.open_failures() >= 1; }));
    std::this_thread::sleep_for(50ms);  // inside the 0.5 s wait
    EXPECT_LT(run.stop(), kPromptStop);
  }
}

TEST(SerialDriver, UnplugAndReplugCountsOneOutageLogsOnceAndTheStreamContinues) {
  Fixture f;
  auto first = std::make_unique<Pty>();
  point_link(f.link, first->slave());
  SerialDriver driver(f.options(0.02, 0.16));
  CollectingSink sink;
  Running run(driver, sink);
  ASSERT_TRUE(eventually([&] { return driver.connected(); }));
  for (int i = 0; i < 5; ++i) first->write(line(1, 0, 0, 0));
  first->write("Q 1 0 0");  // a partial frame when the cable goes
  ASSERT_TRUE(eventually([&] { return sink.size() >= 5; }));
  const int resets_before = f.decoder->resets.load();

  // Unplug: udev removes the by-id link (here: points it nowhere, so that a pty another test
  // opens under the reused /dev/pts number cannot be picked up), and the master goes away: the
  // slave's read fails with EIO / a hangup.
  point_link(f.link, (f.dir / "unplugged").string());
  first->close();
  ASSERT_TRUE(eventually([&] { return driver.outages() == 1 && !driver.connected(); }));
  EXPECT_GT(f.decoder->resets.load(), resets_before);  // the partial frame is forgotten
  std::this_thread::sleep_for(300ms);  // several reopen attempts against a dangling link
  EXPECT_GE(driver.open_failures(), 2u);
  EXPECT_EQ(f.log.count("lost"), 1u) << f.log.all();
  EXPECT_EQ(f.log.count("cannot open"), 0u) << f.log.all();

  // Replug: a new pty, the link re-pointed to it.
  Pty second;
  point_link(f.link, second.slave());
  const Clock::time_point replugged = Clock::now();
  ASSERT_TRUE(eventually([&] { return driver.connected(); }));
  EXPECT_LT(Clock::now() - replugged, 400ms);  // within the backoff (at most 0.16 s) and an open
  EXPECT_EQ(driver.reconnects(), 1u);
  for (int i = 0; i < 5; ++i) second.write(line(0, 1, 0, 0));
  ASSERT_TRUE(eventually([&] { return sink.size() >= 10; }));

  const std::vector<Sample> got = sink.samples();
  ASSERT_EQ(got.size(), 10u);
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].sequence, i);
    if (i > 0) {
      EXPECT_GT(got[i].time, got[i - 1].time);
    }
  }
  EXPECT_NEAR(got[4].orientation.w(), 1.0, 1e-12);  // "Q 1 0 0" + "Q 0 1 0 0" did not merge
  EXPECT_NEAR(got[5].orientation.x(), 1.0, 1e-12);
  EXPECT_EQ(driver.decoder_counters().malformed, 0u);
  EXPECT_EQ(driver.outages(), 1u);
  EXPECT_EQ(driver.device_path(), std::filesystem::canonical(second.slave()).string());
  // The same link state as the daemon's counter lines see it.
  const std::optional<DeviceHealth> health = driver.health();
  ASSERT_TRUE(health.has_value());
  EXPECT_TRUE(health->connected);
  EXPECT_EQ(health->outages, 1u);
  EXPECT_EQ(health->reconnects, 1u);
  EXPECT_EQ(health->open_failures, driver.open_failures());
  EXPECT_EQ(health->frames, driver.decoder_counters().frames);
  EXPECT_EQ(health->frames, 10u);
  EXPECT_LT(run.stop(), kPromptStop);

  // Opened, lost, reopened: one line each.
  const std::vector<LogLine> lines = f.log.lines();
  ASSERT_EQ(lines.size(), 3u) << f.log.all();
  EXPECT_NE(lines[0].text.find("opened"), std::string::npos);
  EXPECT_EQ(lines[1].level, LogLevel::Warn);
  EXPECT_NE(lines[1].text.find("lost the device"), std::string::npos) << lines[1].text;
  EXPECT_EQ(lines[2].level, LogLevel::Info);
  EXPECT_NE(lines[2].text.find("reopened"), std::string::npos) << lines[2].text;
  EXPECT_NE(lines[2].text.find(" after "), std::string::npos) << lines[2].text;
  EXPECT_NE(lines[2].text.find(" attempts"), std::string::npos) << lines[2].text;
}

TEST(SerialDriver, ADeviceAbsentAtStartIsPickedUpWhenItAppears) {
  Fixture f;
  SerialDriver driver(f.options(0.01, 0.08));
  CollectingSink sink;
  Running run(driver, sink);
  std::this_thread::sleep_for(600ms);  // 10, 20, 40, 80, 80, ... ms: about 10 attempts
  EXPECT_GE(driver.open_failures(), 6u);
  EXPECT_FALSE(driver.connected());
  const std::vector<LogLine> waiting = f.log.lines();
  ASSERT_EQ(waiting.size(), 1u) << f.log.all();  // one line, not one per retry
  EXPECT_EQ(waiting[0].level, LogLevel::Warn);
  EXPECT_NE(waiting[0].text.find("cannot open (not found)"), std::string::npos) << waiting[0].text;
  EXPECT_NE(waiting[0].text.find("retrying with backoff 0.01 s .. 0.08 s"), std::string::npos) << waiting[0].text;

  Pty pty;
  point_link(f.link, pty.slave());
  ASSERT_TRUE(eventually([&] { return driver.connected(); }, 500ms));
  EXPECT_EQ(driver.reconnects(), 0u);  // a first open, not a reconnection
  pty.write(line(1, 0, 0, 0));
  ASSERT_TRUE(eventually([&] { return sink.size() == 1; }));
  EXPECT_EQ(sink.samples()[0].sequence, 0u);
  EXPECT_LT(run.stop(), kPromptStop);
  const std::vector<LogLine> lines = f.log.lines();
  ASSERT_EQ(lines.size(), 2u) << f.log.all();
  EXPECT_NE(lines[1].text.find("opened"), std::string::npos);
  EXPECT_NE(lines[1].text.find(" after "), std::string::npos) << lines[1].text;
}

TEST(SerialDriver, DeviceTimeBecomesTrustedAndSpacesTheSamples) {
  Fixture f;
  Pty pty;
  point_link(f.link, pty.slave());
  SerialDriverOptions o = f.options();
  o.time_base.window = 0.4;  // 50 ms blocks: trust after 0.4 s
  o.time_base.qualify_samples = 5;
  o.time_base.latency_slack = 0.02;  // a loaded test machine
  SerialDriver driver(std::move(o));
  CollectingSink sink;
  Running run(driver, sink);
  ASSERT_TRUE(eventually([&] { return driver.connected(); }));
  // 100 Hz for 1 s, two frames per write.
  const Clock::time_point start = Clock::now();
  for (int i = 0; i < 100; i += 2) {
    std::this_thread::sleep_until(start + std::chrono::milliseconds(10 * i));
    pty.write(line(1, 0, 0, 0, 1000.0 + 0.01 * i) + line(1, 0, 0, 0, 1000.0 + 0.01 * (i + 1)));
  }
  ASSERT_TRUE(eventually([&] { return sink.size() >= 100; }));
  EXPECT_TRUE(driver.device_time_trusted());
  const TimeBaseCounters c = driver.time_base_counters();
  EXPECT_EQ(c.qualifications, 1u);
  EXPECT_GT(c.device_samples, 20u);
  const std::vector<Sample> got = sink.samples();
  // The two samples of one write share a receive time but are spaced 10 ms once trusted.
  const Sample& a = got[98];
  const Sample& b = got[99];
  EXPECT_EQ(a.receive_time, b.receive_time);
  EXPECT_NEAR(b.time - a.time, 0.01, 0.01 * 0.02 + 1e-9);
  EXPECT_LT(run.stop(), kPromptStop);
}

TEST(SerialDriver, BadOptionsAreRefused) {
  Fixture f;
  SerialDriverOptions o = f.options();
  o.port.device.clear();
  EXPECT_THROW(SerialDriver{std::move(o)}, std::invalid_argument);
  o = f.options(0.5, 0.1);
  EXPECT_THROW(SerialDriver{std::move(o)}, std::invalid_argument);
  o = f.options();
  o.settings.stop_bits = 3;
  EXPECT_THROW(SerialDriver{std::move(o)}, std::invalid_argument);

  SerialDriverOptions by_name;
  by_name.port.device = "/dev/ttyUSB9";
  by_name.protocol = "no-such-protocol";
  try {
    SerialDriver d(std::move(by_name));
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown protocol 'no-such-protocol' (known: "), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace posefair::drivers
