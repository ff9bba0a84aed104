// The hidraw driver end to end against the kernel (run as root inside the test VM, where
// uhid, hid-generic and hidraw are loaded): a virtual USB HID device made through /dev/uhid
// presents a report descriptor and sends input reports; the real posefaird, configured with
// type = "hid" and the device's USB id, finds its /dev/hidrawN through sysfs, decodes the
// reports and publishes the poses to a UDP collector. Cases: the genuine ST HID Sensor
// orientation descriptor (hid-sensor), a vendor-defined report with a configured layout
// (hid-vendor), and a device destroyed and created again (one outage, logged once, samples
// resume from the new node).
#include <fcntl.h>
#include <linux/input.h>  // BUS_USB
#include <linux/uhid.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "../support/daemon_process.hpp"
#include "../support/hid_descriptor_builder.hpp"
#include "../support/hid_sensor_descriptor.hpp"
#include "../support/test_files.hpp"
#include "posefair/drivers/hid_report_descriptor.hpp"
#include "posefair/drivers/hid_sensor_orientation_decoder.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"

namespace posefair::testing {
namespace {

using namespace std::chrono_literals;

// A virtual HID device on the USB bus, made and removed through /dev/uhid.
class UhidDevice {
 public:
  UhidDevice(std::uint16_t vid, std::uint16_t pid, std::vector<std::uint8_t> descriptor)
      : vid_(vid), pid_(pid), descriptor_(std::move(descriptor)) {
    fd_ = ::open("/dev/uhid", O_RDWR | O_CLOEXEC | O_NONBLOCK);
    if (fd_ < 0) throw std::runtime_error(std::string("/dev/uhid: ") + std::strerror(errno) + " (the uhid module, as root)");
    create();
  }
  ~UhidDevice() {
    destroy();
    ::close(fd_);
  }
  UhidDevice(const UhidDevice&) = delete;
  UhidDevice& operator=(const UhidDevice&) = delete;

  void create() {
    uhid_event ev{};
    ev.type = UHID_CREATE2;
    std::snprintf(reinterpret_cast<char*>(ev.u.create2.name), sizeof ev.u.create2.name, "posefair test %04x:%04x", vid_, pid_);
    ev.u.create2.rd_size = static_cast<std::uint16_t>(descriptor_.size());
    ev.u.create2.bus = BUS_USB;
    ev.u.create2.vendor = vid_;
    ev.u.create2.product = pid_;
    std::memcpy(ev.u.create2.rd_data, descriptor_.data(), descriptor_.size());
    write_event(ev);
    created_ = true;
  }

  void destroy() {
    if (!created_) return;
    uhid_event ev{};
    ev.type = UHID_DESTROY;
    write_event(ev);
    created_ = false;
  }

  void send(const std::vector<std::uint8_t>& report) {
    drain();
    uhid_event ev{};
    ev.type = UHID_INPUT2;
    ev.u.input2.size = static_cast<std::uint16_t>(report.size());
    std::memcpy(ev.u.input2.data, report.data(), report.size());
    write_event(ev);
  }

  // "HID_ID=0003:00000483:00005750": the line of this device's uevent in sysfs.
  std::string hid_id() const {
    char buf[40];
    std::snprintf(buf, sizeof buf, "HID_ID=0003:%08X:%08X", vid_, pid_);
    return buf;
  }

 private:
  void write_event(const uhid_event& ev) {
    if (::write(fd_, &ev, sizeof ev) != static_cast<ssize_t>(sizeof ev))
      throw std::runtime_error(std::string("uhid write: ") + std::strerror(errno));
  }
  // The kernel's events to the device (start, open, close): read so its queue never fills.
  void drain() {
    uhid_event ev{};
    while (::read(fd_, &ev, sizeof ev) > 0) {
    }
  }

  int fd_ = -1;
  std::uint16_t vid_, pid_;
  std::vector<std::uint8_t> descriptor_;
  bool created_ = false;
};

// The /dev/hidrawN of the device with this HID_ID line, once it has appeared (nodes appear
// asynchronously); nullopt while there is none.
std::optional<std::string> hidraw_node(const std::string& hid_id) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it("/sys/class/hidraw", ec), end; !ec && it != end; it.increment(ec)) {
    if (slurp(it->path() / "device" / "uevent").find(hid_id + "\n") == std::string::npos) continue;
    const std::string node = "/dev/" + it->path().filename().string();
    if (std::filesystem::exists(node)) return node;
  }
  return std::nullopt;
}

std::string wait_for_node(const UhidDevice& device) {
  std::optional<std::string> node;
  EXPECT_TRUE(wait_until([&] { return (node = hidraw_node(device.hid_id())).has_value(); }, 30s))
      << "no hidraw node with " << device.hid_id() << " in /sys/class/hidraw (is hid-generic loaded?)";
  return node.value_or("");
}

std::string daemon_config(std::uint16_t port, const std::string& driver) {
  return "[logging]\nstatus_interval = 0\n\n[[stream]]\nid = 1\nname = \"imu\"\ndriver = { type = \"hid\", " + driver +
         ", reconnect_min = 0.05, reconnect_max = 0.2 }\n\n[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(port) +
         "\"]\n";
}

// Sends `count` reports at about 100 Hz.
void send_reports(UhidDevice& device, const std::vector<std::uint8_t>& report, int count) {
  for (int i = 0; i < count; ++i) {
    device.send(report);
    std::this_thread::sleep_for(10ms);
  }
}

// Every published pose is q (or -q) within tol.
void expect_all_near(const Collector& poses, const Quat& q, double tol) {
  for (const Collector::Got& g : poses.all()) {
    const double dot = std::abs(g.m.orientation.coeffs().dot(q.coeffs()));
    ASSERT_NEAR(dot, 1.0, tol) << "pose " << g.m.sequence << ": " << g.m.orientation.coeffs().transpose();
  }
}

drivers::HidOrientationLayout st_layout() {
  const auto parsed = drivers::parse_hid_report_descriptor(kStImuOrientationDescriptor);
  return drivers::resolve_hid_orientation_layout(std::get<drivers::HidReportDescriptor>(parsed));
}

TEST(HidrawDaemon, TheGenuineStSensorDescriptorIsFoundByUsbIdDecodedAndPublished) {
  ScratchDir dir("posefair-hid-");
  UhidDevice device(0x0483, 0x5750, {kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end()});
  const std::string node = wait_for_node(device);
  ASSERT_FALSE(node.empty());
  Collector poses;
  write_text(dir / "posefaird.toml", daemon_config(poses.port(), "usb = \"0483:5750\", protocol = \"hid-sensor\""));
  Subprocess d(daemon_args(dir / "posefaird.toml"), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream 'imu': opened usb 0483:5750 -> " + node +
                                          ", protocol hid-sensor (input report 8 of 20 bytes)", 30s))
      << d.err();

  const Quat q = Quat(0.8, 0.2, -0.4, 0.4).normalized();
  send_reports(device, drivers::encode_hid_orientation_report(st_layout(), q), 150);
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 140 || !d.running(); }, 30s)) << poses.count(1) << "\n" << d.err();
  expect_all_near(poses, q, 1e-6);
  const auto counters = counters_once_received(d, "imu", 1, 150, 10s);
  ASSERT_TRUE(counters) << d.err();
  EXPECT_NE(counters->line.find("; device connected, outages 0, reconnects 0"), std::string::npos) << counters->line;
  EXPECT_EQ(counters->received, 150u) << counters->line;
  EXPECT_NE(counters->line.find(", frames 150, bad 0,"), std::string::npos) << counters->line;
  d.send_signal(SIGTERM);
  EXPECT_EQ(d.wait(30s), 0) << d.err();
}

TEST(HidrawDaemon, AVendorReportIsReadWithTheConfiguredLayout) {
  ScratchDir dir("posefair-hid-");
  // Vendor page 0xFF00, input report 1 of 8 opaque bytes: the descriptor says nothing of a quaternion.
  HidDescriptorBuilder b;
  b.usage_page(0xFF00).usage(0x01).collection(0x01).report_id(1);
  b.usage(0x02).logical_min(0).logical_max(255).report_size(8).report_count(8).input(0x02).end_collection();
  UhidDevice device(0x1209, 0xC0DE, b.out);
  const std::string node = wait_for_node(device);
  ASSERT_FALSE(node.empty());
  Collector poses;
  write_text(dir / "posefaird.toml",
             daemon_config(poses.port(), "usb = \"1209:c0de\", protocol = \"hid-vendor\", report_id = 1, value_type = \"int16\", "
                                         "byte_order = \"big\", offsets = [0, 2, 4, 6], order = \"w-last\", scale = 6.103515625e-05"));
  Subprocess d(daemon_args(dir / "posefaird.toml"), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream 'imu': opened usb 1209:c0de -> " + node + ", protocol hid-vendor", 30s)) << d.err();

  drivers::HidVendorLayout layout;
  layout.report_id = 1;
  layout.big_endian = true;
  layout.w_first = false;
  const Quat q = Quat(0.5, -0.5, 0.5, 0.5);
  send_reports(device, drivers::encode_hid_vendor_report(layout, q), 100);
  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 90 || !d.running(); }, 30s)) << poses.count(1) << "\n" << d.err();
  expect_all_near(poses, q, 1e-6);
  const auto counters = counters_once_received(d, "imu", 1, 100, 10s);
  ASSERT_TRUE(counters) << d.err();
  EXPECT_NE(counters->line.find("; device connected, outages 0, reconnects 0"), std::string::npos) << counters->line;
  EXPECT_EQ(counters->received, 100u) << counters->line;
  EXPECT_NE(counters->line.find(", frames 100, bad 0,"), std::string::npos) << counters->line;
  d.send_signal(SIGTERM);
  EXPECT_EQ(d.wait(30s), 0) << d.err();
}

TEST(HidrawDaemon, ADeviceDestroyedAndCreatedAgainIsOneOutageAndSamplesResume) {
  ScratchDir dir("posefair-hid-");
  UhidDevice device(0x0483, 0x5751, {kStImuOrientationDescriptor.begin(), kStImuOrientationDescriptor.end()});
  ASSERT_FALSE(wait_for_node(device).empty());
  Collector poses;
  write_text(dir / "posefaird.toml", daemon_config(poses.port(), "usb = \"0483:5751\", protocol = \"hid-sensor\""));
  Subprocess d(daemon_args(dir / "posefaird.toml"), dir / "d.out", dir / "d.err");
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream 'imu': opened usb 0483:5751 -> ", 30s)) << d.err();
  const Quat q = Quat(0.8, 0.2, -0.4, 0.4).normalized();
  const std::vector<std::uint8_t> report = drivers::encode_hid_orientation_report(st_layout(), q);
  send_reports(device, report, 60);

  // Unplug: the driver sees the node go, counts one outage and says so once.
  device.destroy();
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream 'imu': lost the device", 30s)) << d.err();
  ASSERT_TRUE(wait_until([&] { return !hidraw_node(device.hid_id()).has_value(); }, 30s));
  std::this_thread::sleep_for(500ms);  // the driver retries meanwhile (logging nothing more)
  device.create();
  const std::string node = wait_for_node(device);
  ASSERT_FALSE(node.empty());
  ASSERT_TRUE(wait_for_log_or_exit(d, "stream 'imu': reopened usb 0483:5751 -> " + node + " after ", 30s)) << d.err();
  send_reports(device, report, 60);

  ASSERT_TRUE(wait_until([&] { return poses.count(1) >= 100 || !d.running(); }, 30s)) << poses.count(1) << "\n" << d.err();
  expect_all_near(poses, q, 1e-6);
  const auto counters = counters_once_received(d, "imu", 1, 120, 10s);
  ASSERT_TRUE(counters) << d.err();
  EXPECT_NE(counters->line.find("; device connected, outages 1, reconnects 1"), std::string::npos) << counters->line;
  EXPECT_EQ(counters->received, 120u) << counters->line;
  EXPECT_NE(counters->line.find(", frames 120, bad 0,"), std::string::npos) << counters->line;
  EXPECT_EQ(count_of(d.err(), "lost the device"), 1u) << d.err();
  EXPECT_EQ(count_of(d.err(), "cannot open"), 0u) << "a wait after a loss is announced by the loss line only\n" << d.err();
  d.send_signal(SIGTERM);
  EXPECT_EQ(d.wait(30s), 0) << d.err();
}

}  // namespace
}  // namespace posefair::testing
