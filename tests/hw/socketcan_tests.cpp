// The SocketCAN driver against the kernel's CAN stack (vcan, can-raw), inside the test VM as
// root. Each test creates its own vcan interface (a name of its own) and deletes it at the end.
//
// SocketCanDriver (no daemon): kernel filters, CAN FD, receive timestamps, error frames, the
// interface going down and up, deleted and re-added, and absent at start.
// SocketCanDaemon: the real posefaird with three CAN streams on one vcan, fed by independent
// peers (can-utils cansend and canplayer, python3-can), its poses collected over UDP.
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <signal.h>
#include <grp.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "../support/daemon_process.hpp"
#include "../support/test_files.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/drivers/dronecan_ahrs_decoder.hpp"
#include "posefair/drivers/posefair_can_decoder.hpp"
#include "posefair/drivers/socketcan_driver.hpp"
#include "posefair/drivers/xsens_can_decoder.hpp"
#include "posefair/formats/candump_log.hpp"

namespace posefair::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using drivers::CanFrame;

const std::string kIp = "/usr/bin/ip";

int sh(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

double monotonic_now() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// A vcan interface of the test's own, up, removed at the end (also when the test failed).
class Vcan {
 public:
  explicit Vcan(std::string name, bool fd = false, bool create_now = true) : name_(std::move(name)), fd_(fd) {
    if (create_now) add();
  }
  ~Vcan() { sh(kIp + " link del dev " + name_ + " 2>/dev/null"); }
  Vcan(const Vcan&) = delete;
  Vcan& operator=(const Vcan&) = delete;

  const std::string& name() const { return name_; }
  void add() {
    if (sh(kIp + " link add dev " + name_ + " type vcan") != 0) throw std::runtime_error("cannot add vcan " + name_);
    if (fd_ && sh(kIp + " link set " + name_ + " mtu 72") != 0) throw std::runtime_error("cannot set mtu 72 on " + name_);
    up();
  }
  void up() {
    if (sh(kIp + " link set " + name_ + " up") != 0) throw std::runtime_error("cannot set " + name_ + " up");
  }
  void down() {
    if (sh(kIp + " link set " + name_ + " down") != 0) throw std::runtime_error("cannot set " + name_ + " down");
  }
  void remove() {
    if (sh(kIp + " link del dev " + name_) != 0) throw std::runtime_error("cannot delete " + name_);
  }

 private:
  std::string name_;
  bool fd_;
};

// A raw CAN socket of the test: writes frames (classic or FD, error frames included) and can
// count what reaches an unfiltered socket.
class RawCan {
 public:
  RawCan(const std::string& interface, bool fd) {
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) throw std::runtime_error("socket(PF_CAN): " + std::string(std::strerror(errno)));
    if (fd) {
      const int on = 1;
      ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on);
    }
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(::if_nametoindex(interface.c_str()));
    if (addr.can_ifindex == 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0)
      throw std::runtime_error("bind to " + interface + ": " + std::strerror(errno));
  }
  ~RawCan() { ::close(fd_); }
  RawCan(const RawCan&) = delete;
  RawCan& operator=(const RawCan&) = delete;

  // 0 or the errno of the write.
  int send(const CanFrame& f) {
    if (f.fd) {
      canfd_frame raw{};
      raw.can_id = f.can_id;
      raw.len = f.len;
      raw.flags = f.fd_flags;
      std::memcpy(raw.data, f.data.data(), f.len);
      return ::write(fd_, &raw, sizeof raw) == static_cast<ssize_t>(sizeof raw) ? 0 : errno;
    }
    can_frame raw{};
    raw.can_id = f.can_id;
    raw.len = f.len;
    std::memcpy(raw.data, f.data.data(), f.len);
    return ::write(fd_, &raw, sizeof raw) == static_cast<ssize_t>(sizeof raw) ? 0 : errno;
  }
  void send_all(const std::vector<CanFrame>& frames) {
    for (const CanFrame& f : frames) {
      const int e = send(f);
      ASSERT_EQ(e, 0) << "write of a frame with id 0x" << std::hex << f.can_id << ": " << std::strerror(e);
    }
  }
  // Frames waiting on this socket (it reads everything: no filter), read without blocking.
  std::size_t drain() {
    std::size_t n = 0;
    canfd_frame raw{};
    while (::recv(fd_, &raw, sizeof raw, MSG_DONTWAIT) > 0) ++n;
    return n;
  }

 private:
  int fd_ = -1;
};

class SampleVector final : public drivers::SampleSink {
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
  std::vector<Sample> all() const {
    std::lock_guard lock(mutex_);
    return samples_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Sample> samples_;
};

class LogLines {
 public:
  drivers::DriverLog sink() {
    return [this](drivers::LogLevel, std::string_view line) {
      std::lock_guard lock(mutex_);
      lines_.emplace_back(line);
    };
  }
  std::size_t count(const std::string& needle) const {
    std::lock_guard lock(mutex_);
    std::size_t n = 0;
    for (const std::string& l : lines_) n += l.find(needle) != std::string::npos ? 1 : 0;
    return n;
  }
  std::string text() const {
    std::lock_guard lock(mutex_);
    std::string s;
    for (const std::string& l : lines_) s += l + "\n";
    return s;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
};

// A driver on its own thread, stopped and joined at the end.
struct Running {
  drivers::SocketCanDriver driver;
  SampleVector samples;
  std::jthread thread;
  explicit Running(drivers::SocketCanDriverOptions o)
      : driver(std::move(o)), thread([this](std::stop_token stop) { driver.run(stop, samples); }) {}
};

drivers::SocketCanDriverOptions options(const std::string& interface, const std::string& protocol, LogLines& log,
                                        bool fd = false) {
  drivers::SocketCanDriverOptions o;
  o.interface = interface;
  o.protocol = protocol;
  o.fd = fd;
  o.reconnect_min = 0.05;
  o.reconnect_max = 0.2;
  o.time_source = drivers::TimeSource::Receive;
  o.log = log.sink();
  return o;
}

Quat turn(double angle) { return Quat(Eigen::AngleAxisd(angle, Vec3(0, 0, 1))); }

// The QUATERNION frame of posefair-can at base 0x200 (no time, no position).
std::vector<CanFrame> posefair_quaternion(double angle) {
  return drivers::encode_posefair_can(0x200, false, turn(angle), std::nullopt, nullptr, 0);
}

TEST(SocketCanDriver, KernelFiltersKeepForeignFramesOffTheSocket) {
  Vcan bus("pfcanfilt");
  LogLines log;
  Running r(options(bus.name(), "posefair-can", log));
  ASSERT_TRUE(wait_until([&] { return r.driver.connected(); }, 10s)) << log.text();
  RawCan sender(bus.name(), false);
  RawCan everything(bus.name(), false);
  const std::uint8_t bytes[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  for (int k = 0; k < 10; ++k) {
    sender.send_all({CanFrame::make(0x123, false, bytes), CanFrame::make(0x7FF, false, bytes),
                     CanFrame::make(0x204, false, bytes), CanFrame::make(0x202, true, bytes)});  // B+4; B+2 as 29-bit
    sender.send_all(posefair_quaternion(0.01 * k));
  }
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 10; }, 10s)) << log.text();
  // The counter snapshots are published after each batch of reads, just after its samples.
  ASSERT_TRUE(wait_until([&] { return r.driver.frame_counters().received >= 10; }, 10s));
  // The frames were on the bus (an unfiltered socket saw all 50) ...
  EXPECT_EQ(everything.drain(), 50u);
  // ... but the driver's socket got only its own: the decoder counted no foreign frame.
  EXPECT_EQ(r.driver.frames(), 10u);
  EXPECT_EQ(r.driver.frame_counters().received, 10u);
  EXPECT_EQ(r.driver.frame_counters().foreign, 0u);
  EXPECT_EQ(r.driver.decoder_counters().frames, 10u);
  const std::vector<Sample> s = r.samples.all();
  ASSERT_EQ(s.size(), 10u);
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_EQ(s[k].sequence, k);
    EXPECT_LT(so3::rotation_angle(s[k].orientation, turn(0.01 * static_cast<double>(k))), 1e-3);
  }
}

TEST(SocketCanDriver, ReceiveTimesAreKernelTimestampsOnTheMonotonicClock) {
  Vcan bus("pfcantime");
  LogLines log;
  Running r(options(bus.name(), "posefair-can", log));
  ASSERT_TRUE(wait_until([&] { return r.driver.connected(); }, 10s)) << log.text();
  RawCan sender(bus.name(), false);
  for (std::size_t k = 0; k < 5; ++k) {
    const double before = monotonic_now();
    sender.send_all(posefair_quaternion(0.1));
    ASSERT_TRUE(wait_until([&] { return r.samples.size() > k; }, 10s)) << log.text();
    const double after = monotonic_now();
    const Sample s = r.samples.all()[k];
    EXPECT_GE(s.receive_time, before) << "sample " << k;
    EXPECT_LE(s.receive_time, after) << "sample " << k;
    EXPECT_GE(s.time, s.receive_time);  // time source "receive": the receive time (nudged only if repeated)
    EXPECT_LE(s.time, after);
    std::this_thread::sleep_for(20ms);  // spacing between the samples, not a wait for a result
  }
}

TEST(SocketCanDriver, FdFramesArriveOnlyWhenFdIsConfigured) {
  Vcan bus("pfcanfd", /*fd=*/true);
  LogLines log_fd, log_classic;
  Running with_fd(options(bus.name(), "posefair-can", log_fd, true));
  Running classic(options(bus.name(), "posefair-can", log_classic, false));
  ASSERT_TRUE(wait_until([&] { return with_fd.driver.connected() && classic.driver.connected(); }, 10s))
      << log_fd.text() << log_classic.text();
  RawCan sender(bus.name(), true);
  CanFrame fd_frame = posefair_quaternion(0.2)[0];
  fd_frame.fd = true;
  fd_frame.fd_flags = CanFrame::kFdBrs;
  sender.send_all({fd_frame});
  sender.send_all(posefair_quaternion(0.3));  // classic, after the FD one
  ASSERT_TRUE(wait_until([&] { return with_fd.samples.size() >= 2 && classic.samples.size() >= 1; }, 10s))
      << log_fd.text() << log_classic.text();
  EXPECT_EQ(with_fd.driver.frames(), 2u);
  EXPECT_EQ(with_fd.driver.fd_frames(), 1u);
  EXPECT_LT(so3::rotation_angle(with_fd.samples.all()[0].orientation, turn(0.2)), 1e-3);
  // The classic socket never saw the FD frame (the kernel does not deliver it without
  // CAN_RAW_FD_FRAMES): its one frame is the classic one.
  EXPECT_EQ(classic.driver.frames(), 1u);
  EXPECT_EQ(classic.driver.fd_frames(), 0u);
  EXPECT_LT(so3::rotation_angle(classic.samples.all()[0].orientation, turn(0.3)), 1e-3);
  EXPECT_EQ(log_fd.count("not in CAN FD mode"), 0u) << log_fd.text();
}

CanFrame error_frame(std::uint32_t classes, std::uint8_t controller = 0) {
  CanFrame f;
  f.can_id = CAN_ERR_FLAG | classes;
  f.len = CAN_ERR_DLC;
  f.data[1] = controller;
  return f;
}

TEST(SocketCanDriver, ErrorFramesAreCountedByClassAndLoggedOncePerChange) {
  Vcan bus("pfcanerr");
  LogLines log;
  Running r(options(bus.name(), "posefair-can", log));
  ASSERT_TRUE(wait_until([&] { return r.driver.connected(); }, 10s)) << log.text();
  RawCan sender(bus.name(), false);
  // vcan loops back whatever a raw socket writes, error frames included (the kernel does not
  // refuse CAN_ERR_FLAG from user space), so a controller's error sequence can be played.
  sender.send_all({error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING), error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING),
                   error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE), error_frame(CAN_ERR_BUSOFF),
                   error_frame(CAN_ERR_BUSOFF), error_frame(CAN_ERR_RESTARTED), error_frame(CAN_ERR_ACK),
                   error_frame(CAN_ERR_ACK)});
  sender.send_all(posefair_quaternion(0.0));  // the marker: everything before it was read
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 1; }, 10s)) << log.text();
  ASSERT_TRUE(wait_until([&] { return r.driver.frame_counters().received >= 9; }, 10s));  // the snapshot, after the samples
  EXPECT_EQ(r.driver.error_frames(), 8u);
  EXPECT_EQ(r.driver.bus_off(), 2u);
  EXPECT_EQ(r.driver.error_class_count(2), 3u);  // controller
  EXPECT_EQ(r.driver.error_class_count(5), 2u);  // no-ack
  EXPECT_EQ(r.driver.error_class_count(6), 2u);  // bus-off
  EXPECT_EQ(r.driver.error_class_count(8), 1u);  // restarted
  EXPECT_EQ(r.driver.frame_counters().errors, 8u);
  // One line per change: warning, passive, bus-off, restarted (-> active), the first no-ack.
  EXPECT_EQ(log.count("error frame ("), 5u) << log.text();
  EXPECT_EQ(log.count("controller error-active -> error-warning"), 1u) << log.text();
  EXPECT_EQ(log.count("controller error-warning -> error-passive"), 1u) << log.text();
  EXPECT_EQ(log.count("controller error-passive -> bus-off"), 1u) << log.text();
  EXPECT_EQ(log.count("controller bus-off -> error-active"), 1u) << log.text();
  EXPECT_EQ(log.count("error frame (no-ack)"), 1u) << log.text();
  // cansend, an independent writer, gets an error frame through as well (8-digit id with the
  // ERR flag: can-utils keeps it an error frame).
  ASSERT_EQ(sh("/usr/bin/cansend " + bus.name() + " 20000004#0004000000000000"), 0);  // controller, rx-warning
  sender.send_all(posefair_quaternion(0.0));
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 2; }, 10s)) << log.text();
  EXPECT_EQ(r.driver.error_frames(), 9u);
  EXPECT_EQ(log.count("controller error-active -> error-warning"), 2u) << log.text();
}

TEST(SocketCanDriver, InterfaceDownAndUpIsOneOutageAndSamplesResume) {
  Vcan bus("pfcandown");
  LogLines log;
  Running r(options(bus.name(), "posefair-can", log));
  ASSERT_TRUE(wait_until([&] { return r.driver.connected(); }, 10s)) << log.text();
  {
    RawCan sender(bus.name(), false);
    sender.send_all(posefair_quaternion(0.1));
  }
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 1; }, 10s)) << log.text();
  bus.down();
  ASSERT_TRUE(wait_until([&] { return r.driver.outages() == 1 && !r.driver.connected(); }, 10s)) << log.text();
  EXPECT_EQ(log.count("lost interface " + bus.name() + " (interface down)"), 1u) << log.text();
  // While it is down, reopening fails (counted, not logged again).
  ASSERT_TRUE(wait_until([&] { return r.driver.open_failures() >= 2; }, 10s)) << log.text();
  EXPECT_EQ(log.count("cannot open"), 0u) << log.text();
  bus.up();
  ASSERT_TRUE(wait_until([&] { return r.driver.connected() && r.driver.reconnects() == 1; }, 10s)) << log.text();
  EXPECT_EQ(log.count("reopened " + bus.name()), 1u) << log.text();
  RawCan sender(bus.name(), false);
  sender.send_all(posefair_quaternion(0.2));
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 2; }, 10s)) << log.text();
  EXPECT_EQ(r.samples.all()[1].sequence, 1u);
  EXPECT_EQ(r.driver.outages(), 1u);
  ASSERT_TRUE(wait_until([&] { return r.driver.decoder_counters().frames >= 2; }, 10s));  // the snapshot, after the samples
  const auto h = r.driver.health();
  ASSERT_TRUE(h.has_value());
  EXPECT_TRUE(h->connected);
  EXPECT_EQ(h->outages, 1u);
  EXPECT_EQ(h->reconnects, 1u);
  EXPECT_EQ(h->frames, 2u);
}

TEST(SocketCanDriver, AnInterfaceAbsentAtStartThenDeletedAndReAddedIsWaitedFor) {
  Vcan bus("pfcandel", false, /*create_now=*/false);
  LogLines log;
  Running r(options(bus.name(), "posefair-can", log));
  ASSERT_TRUE(wait_until([&] { return r.driver.open_failures() >= 2; }, 10s)) << log.text();
  EXPECT_FALSE(r.driver.connected());
  EXPECT_EQ(log.count("no such interface"), 1u) << log.text();  // once, not per retry
  bus.add();
  ASSERT_TRUE(wait_until([&] { return r.driver.connected(); }, 10s)) << log.text();
  EXPECT_EQ(r.driver.outages(), 0u);
  {
    RawCan sender(bus.name(), false);
    sender.send_all(posefair_quaternion(0.1));
  }
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 1; }, 10s)) << log.text();
  bus.remove();
  ASSERT_TRUE(wait_until([&] { return r.driver.outages() == 1 && !r.driver.connected(); }, 10s)) << log.text();
  EXPECT_EQ(log.count("lost interface " + bus.name()), 1u) << log.text();
  bus.add();
  ASSERT_TRUE(wait_until([&] { return r.driver.connected() && r.driver.reconnects() == 1; }, 10s)) << log.text();
  RawCan sender(bus.name(), false);
  sender.send_all(posefair_quaternion(0.2));
  ASSERT_TRUE(wait_until([&] { return r.samples.size() >= 2; }, 10s)) << log.text();
  EXPECT_EQ(r.driver.outages(), 1u);
}

// What docs/can-devices.md says about permissions, checked: a process that is not root and
// has no capability at all opens a raw CAN socket, binds it and reads a frame.
TEST(SocketCanPermissions, AnUnprivilegedProcessReadsARawCanSocket) {
  Vcan bus("pfcanuser");
  const unsigned ifindex = ::if_nametoindex(bus.name().c_str());
  ASSERT_NE(ifindex, 0u);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // only async-signal-safe calls from here on
    ::close(ready[0]);
    if (::setgroups(0, nullptr) != 0 || ::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(10);
    const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);  // nobody, no capabilities (setuid cleared them)
    if (s < 0) ::_exit(11);
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(ifindex);
    if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) ::_exit(12);
    if (::write(ready[1], "x", 1) != 1) ::_exit(13);
    pollfd p{s, POLLIN, 0};
    if (::poll(&p, 1, 20000) != 1) ::_exit(14);
    can_frame f{};
    ::_exit(::read(s, &f, sizeof f) == static_cast<ssize_t>(sizeof f) && f.can_id == 0x321 ? 0 : 15);
  }
  ::close(ready[1]);
  pollfd p{ready[0], POLLIN, 0};
  char byte = 0;
  const bool bound = ::poll(&p, 1, 20000) == 1 && ::read(ready[0], &byte, 1) == 1;
  ::close(ready[0]);
  if (bound) {
    RawCan sender(bus.name(), false);
    const std::uint8_t bytes[2] = {0xAB, 0xCD};
    sender.send_all({CanFrame::make(0x321, false, bytes)});
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  // 10: cannot drop to nobody; 11: socket() refused; 12: bind() refused; 14/15: no frame.
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_TRUE(bound);
}

// --- the daemon with independent peers ---

constexpr int kPeerSamples = 20;  // per stream, 10 ms apart in device time

Quat stream_orientation(int stream, int k) {
  const Vec3 axis = stream == 1 ? Vec3(0, 0, 1) : stream == 2 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  return Quat(Eigen::AngleAxisd(0.3 * stream + 0.01 * k, axis));
}

// "123#11223344" from a frame (can-utils' compact form, as cansend takes it).
std::string compact(const CanFrame& f) {
  const std::string line = formats::format_candump_line(f, "x");
  return line.substr(line.rfind(' ') + 1);
}

TEST(SocketCanDaemon, CansendCanplayerAndPythonCanFramesArePublishedAsPoses) {
  Vcan bus("pfcand");
  ScratchDir dir("posefair-hw-can-");
  Collector poses;
  const fs::path config = dir / "posefaird.toml";
  const std::string driver = "type = \"socketcan\", interface = \"" + bus.name() +
                             "\", time_source = \"device\", reconnect_min = 0.05, reconnect_max = 0.5";
  write_text(config, "[logging]\nstatus_interval = 0\n[engine]\nepsilon_r = 0.02\n\n"
                     "[[stream]]\nid = 1\nname = \"glove\"\ndriver = { " + driver +
                     ", protocol = \"posefair-can\", posefair_base_id = 0x204 }\n\n"
                     "[[stream]]\nid = 2\nname = \"mti\"\ndriver = { " + driver + ", protocol = \"xsens-can\" }\n\n"
                     "[[stream]]\nid = 3\nname = \"ahrs\"\ndriver = { " + driver +
                     ", protocol = \"dronecan-ahrs\", dronecan_node_id = 42 }\n\n"
                     "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(poses.port()) + "\"]\n");
  Subprocess d(daemon_args(config), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_until([&] { return count_of(d.err(), "': opened " + bus.name()) >= 3 || !d.running(); }, 20s))
      << d.err();

  // posefair-can with cansend: TIME (B) then QUATERNION (B + 2) per sample, one cansend per
  // frame, all from one shell script (a shell per frame is slow under emulation).
  std::string script = "set -e\n";
  for (int k = 0; k < kPeerSamples; ++k) {
    for (const CanFrame& f : drivers::encode_posefair_can(0x204, false, stream_orientation(1, k),
                                                          1000000u + 10000u * static_cast<std::uint32_t>(k), nullptr,
                                                          static_cast<std::uint8_t>(k)))
      script += "/usr/bin/cansend " + bus.name() + " " + compact(f) + "\n";
  }
  write_text(dir / "glove.sh", script);
  ASSERT_EQ(sh("/bin/sh " + (dir / "glove.sh").string()), 0);
  // xsens-can with canplayer: a candump log played at its own pace (1 ms between frames).
  std::string log;
  double t = 1700000000.0;
  for (int k = 0; k < kPeerSamples; ++k)
    for (const CanFrame& f : drivers::encode_xsens_can(stream_orientation(2, k), 100u * static_cast<std::uint32_t>(k),
                                                       static_cast<std::uint16_t>(k), (t += 0.001)))
      log += formats::format_candump_line(f, bus.name()) + "\n";
  write_text(dir / "mti.log", log);
  ASSERT_EQ(sh("/usr/bin/canplayer -I " + (dir / "mti.log").string()), 0);
  // dronecan-ahrs with python-can: multi-frame transfers, the frames listed in a file.
  std::string frames;
  for (int k = 0; k < kPeerSamples; ++k) {
    const std::vector<std::uint8_t> payload =
        drivers::serialize_dronecan_ahrs_solution(stream_orientation(3, k), 3000000u + 10000u * static_cast<std::uint64_t>(k));
    for (const CanFrame& f : drivers::encode_dronecan_transfer(drivers::kDroneCanAhrsSolutionId,
                                                               drivers::kDroneCanAhrsSolutionSignature, payload, 42,
                                                               static_cast<std::uint8_t>(k & 31)))
      frames += compact(f) + "\n";
  }
  write_text(dir / "ahrs.frames", frames);
  write_text(dir / "send.py",
             "import sys, can\n"
             "with can.Bus(interface='socketcan', channel=sys.argv[1]) as bus:\n"
             "    for line in open(sys.argv[2]):\n"
             "        ident, data = line.strip().split('#')\n"
             "        bus.send(can.Message(arbitration_id=int(ident, 16), data=bytes.fromhex(data), is_extended_id=True))\n");
  ASSERT_EQ(sh("/usr/bin/python3 " + (dir / "send.py").string() + " " + bus.name() + " " + (dir / "ahrs.frames").string()), 0);

  ASSERT_TRUE(wait_until([&] { return poses.count(1) + poses.count(2) + poses.count(3) >= 3u * kPeerSamples; }, 20s))
      << poses.count(1) << " " << poses.count(2) << " " << poses.count(3) << "\n" << d.err();
  std::vector<int> seen(4, 0);
  std::vector<std::vector<double>> times(4, std::vector<double>(kPeerSamples, 0.0));
  for (const Collector::Got& g : poses.all()) {
    const std::uint32_t s = g.m.stream;
    ASSERT_GE(s, 1u);
    ASSERT_LE(s, 3u);
    const int k = static_cast<int>(g.m.sequence);
    ASSERT_LT(k, kPeerSamples);
    ++seen[s];
    EXPECT_LE(so3::rotation_angle(g.m.orientation, stream_orientation(static_cast<int>(s), k)), 0.02 + 2e-3)
        << "stream " << s << " pose " << k;
    times[s][static_cast<std::size_t>(k)] = g.m.sample_time;
  }
  // time_source = "device": the sample times are spaced as the device clocks were (10 ms,
  // within the time base's ±2 % slew, time_base.hpp step 7), not as the peers' frames happened
  // to arrive (canplayer: 3 ms per sample; python-can and cansend: as fast as they run).
  for (int s = 1; s <= 3; ++s)
    for (int k = 1; k < kPeerSamples; ++k)
      EXPECT_NEAR(times[s][k] - times[s][k - 1], 0.01, 0.01 * 0.02 + 1e-6) << "stream " << s << " pose " << k;
  EXPECT_EQ(seen[1], kPeerSamples);
  EXPECT_EQ(seen[2], kPeerSamples);
  EXPECT_EQ(seen[3], kPeerSamples);

  d.send_signal(SIGUSR1);
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream ahrs (id 3, ", 10s)) << d.err();
  for (const auto& [name, id, protocol] :
       {std::tuple{"glove", 1u, "posefair-can"}, std::tuple{"mti", 2u, "xsens-can"}, std::tuple{"ahrs", 3u, "dronecan-ahrs"}}) {
    const auto c = last_counters(d.err(), name, id);
    ASSERT_TRUE(c.has_value()) << d.err();
    EXPECT_EQ(c->received, static_cast<std::uint64_t>(kPeerSamples)) << c->line;
    EXPECT_NE(c->line.find("socketcan:" + bus.name() + " (" + protocol + ")"), std::string::npos) << c->line;
    EXPECT_NE(c->line.find("; device connected, outages 0, reconnects 0"), std::string::npos) << c->line;
  }
  d.send_signal(SIGTERM);
  EXPECT_EQ(d.wait(20s), 0) << d.err();
}

}  // namespace
}  // namespace posefair::testing
