// The hidraw driver's host-testable parts: the sysfs uevent parser, finding nodes by HID id
// in a fake sysfs tree, the options it refuses, and its waiting for an absent device (logged
// once, counted, stopped promptly). Reading a real hidraw node needs the kernel's uhid: those
// tests are tests/hw/hidraw_tests.cpp, run inside the VM.
#include "posefair/drivers/hidraw_driver.hpp"
#include "posefair/drivers/hid_vendor_layout_decoder.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "../support/test_files.hpp"

namespace posefair::drivers {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::ScratchDir;

TEST(HidUevent, ReadsTheBusVendorProductNameAndSerial) {
  const auto u = parse_hid_uevent(
      "DRIVER=hid-generic\nHID_ID=0003:00000483:00005750\nHID_NAME=STMicroelectronics IMU\n"
      "HID_PHYS=usb-0000:00:14.0-2/input0\nHID_UNIQ=2053386B5650\nMODALIAS=hid:b0003g0001v00000483p00005750\n");
  ASSERT_TRUE(u);
  EXPECT_EQ(u->bus, 0x0003);
  EXPECT_EQ(u->vendor, 0x0483);
  EXPECT_EQ(u->product, 0x5750);
  EXPECT_EQ(u->name, "STMicroelectronics IMU");
  EXPECT_EQ(u->uniq, "2053386B5650");
}

TEST(HidUevent, AcceptsLowerCaseHexAndAnEmptyUniq) {
  const auto u = parse_hid_uevent("HID_ID=0005:0000046d:0000b01a\r\nHID_UNIQ=\r\n");
  ASSERT_TRUE(u);
  EXPECT_EQ(u->bus, 0x0005);
  EXPECT_EQ(u->vendor, 0x046D);
  EXPECT_EQ(u->product, 0xB01A);
  EXPECT_EQ(u->uniq, "");
}

TEST(HidUevent, RefusesTextWithoutAWellFormedHidId) {
  EXPECT_FALSE(parse_hid_uevent(""));
  EXPECT_FALSE(parse_hid_uevent("HID_NAME=x\n"));
  EXPECT_FALSE(parse_hid_uevent("HID_ID=0003:00000483\n"));             // two fields
  EXPECT_FALSE(parse_hid_uevent("HID_ID=0003:00010483:00005750\n"));    // vendor above 16 bits
  EXPECT_FALSE(parse_hid_uevent("HID_ID=0003:0000048g:00005750\n"));    // not hex
  EXPECT_FALSE(parse_hid_uevent("HID_ID=0003::00005750\n"));            // empty vendor
  EXPECT_FALSE(parse_hid_uevent("HID_ID=00003:00000483:00005750\n"));   // bus of 5 digits
  EXPECT_FALSE(parse_hid_uevent("HID_ID=0003:000000483:00005750\n"));   // vendor of 9 digits
}

// A fake /sys/class/hidraw with one uevent per node.
struct FakeSysfs {
  ScratchDir dir{"posefair-hidraw-"};
  fs::path sys() const { return dir.path() / "sys"; }
  fs::path dev() const { return dir.path() / "dev"; }
  void add(const std::string& node, const std::string& uevent) {
    const fs::path d = sys() / "class" / "hidraw" / node / "device";
    fs::create_directories(d);
    std::ofstream(d / "uevent") << uevent;
  }
};

TEST(FindHidrawNodes, MatchesVendorProductAndSerialInNodeNumberOrder) {
  FakeSysfs f;
  f.add("hidraw10", "HID_ID=0003:00000483:00005750\nHID_UNIQ=B\n");
  f.add("hidraw2", "HID_ID=0003:00000483:00005750\nHID_UNIQ=A\n");
  f.add("hidraw0", "HID_ID=0003:0000046D:0000C52B\nHID_UNIQ=\n");
  f.add("hidraw3", "garbage\n");
  f.add("hidrawX", "HID_ID=0003:00000483:00005750\n");  // not a hidraw node name
  HidDeviceSpec spec;
  spec.usb = UsbId{0x0483, 0x5750};
  const std::string dev = f.dev().string();
  EXPECT_EQ(find_hidraw_nodes(spec, f.sys(), f.dev()), (std::vector<std::string>{dev + "/hidraw2", dev + "/hidraw10"}));
  spec.serial = "B";
  EXPECT_EQ(find_hidraw_nodes(spec, f.sys(), f.dev()), (std::vector<std::string>{dev + "/hidraw10"}));
  spec.serial = "C";
  EXPECT_TRUE(find_hidraw_nodes(spec, f.sys(), f.dev()).empty());
  spec.serial.clear();
  spec.usb = UsbId{0x046D, 0xC52B};
  EXPECT_EQ(find_hidraw_nodes(spec, f.sys(), f.dev()), (std::vector<std::string>{dev + "/hidraw0"}));
}

TEST(FindHidrawNodes, FindsNothingWithoutSysfs) {
  HidDeviceSpec spec;
  spec.usb = UsbId{0x0483, 0x5750};
  EXPECT_TRUE(find_hidraw_nodes(spec, "/nonexistent-sysfs", "/dev").empty());
}

TEST(HidrawDriverOptions, RefusesWhatCannotWork) {
  auto make = [](auto edit) {
    HidrawDriverOptions o;
    o.device.device = "/dev/hidraw0";
    edit(o);
    return HidrawDriver(std::move(o));
  };
  EXPECT_THROW(make([](HidrawDriverOptions& o) { o.device.device.clear(); }), std::invalid_argument);
  EXPECT_THROW(make([](HidrawDriverOptions& o) { o.reconnect_min = 0.0; }), std::invalid_argument);
  EXPECT_THROW(make([](HidrawDriverOptions& o) { o.reconnect_max = 0.01; }), std::invalid_argument);
  EXPECT_THROW(make([](HidrawDriverOptions& o) { o.decoder_options["component_order"] = std::string("xyzz"); }), std::invalid_argument);
  EXPECT_THROW(make([](HidrawDriverOptions& o) { o.decoder_options["report_id"] = std::int64_t{256}; }), std::invalid_argument);
  EXPECT_THROW(make([](HidrawDriverOptions& o) {
                 o.protocol = "hid-vendor";
                 o.decoder_options["offsets"] = std::vector<std::int64_t>{0, 2, 4, 6};
                 o.decoder_options["report_id"] = std::int64_t{0};
               }),
               HidVendorLayoutError);
  EXPECT_NO_THROW(make([](HidrawDriverOptions&) {}));
  EXPECT_EQ(make([](HidrawDriverOptions&) {}).name(), "hid:/dev/hidraw0");
}

class NullSink final : public SampleSink {
 public:
  bool push(const Sample&) override { return true; }
};

struct LogCapture {
  std::mutex mutex;
  std::vector<std::string> lines;
  DriverLog sink() {
    return [this](LogLevel, std::string_view m) {
      std::lock_guard lock(mutex);
      lines.emplace_back(m);
    };
  }
  std::vector<std::string> all() {
    std::lock_guard lock(mutex);
    return lines;
  }
};

// Runs the driver on its own thread until stopped; true when run() returned within `bound`.
bool run_for(HidrawDriver& driver, std::chrono::milliseconds how_long, std::chrono::milliseconds bound) {
  NullSink sink;
  std::jthread t([&](std::stop_token st) { driver.run(st, sink); });
  std::this_thread::sleep_for(how_long);
  const auto asked = std::chrono::steady_clock::now();
  t.request_stop();
  t.join();
  return std::chrono::steady_clock::now() - asked < bound;
}

TEST(HidrawDriver, WaitsForAnAbsentDeviceLoggingItOnceAndStopsPromptly) {
  FakeSysfs f;
  LogCapture logs;
  HidrawDriverOptions o;
  o.device.usb = UsbId{0x0483, 0x5750};
  o.sysfs_root = f.sys();
  o.dev_root = f.dev();
  o.reconnect_min = 0.01;
  o.reconnect_max = 0.02;
  o.log = logs.sink();
  HidrawDriver d(std::move(o));
  EXPECT_TRUE(run_for(d, 300ms, 2s));
  EXPECT_GE(d.open_failures(), 3u);
  EXPECT_FALSE(d.connected());
  const auto lines = logs.all();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "cannot open: no hidraw node with HID id usb 0483:5750; retrying with backoff 0.01 s .. 0.02 s");
  const auto h = d.health();
  ASSERT_TRUE(h);
  EXPECT_EQ(h->open_failures, d.open_failures());
  EXPECT_EQ(h->outages, 0u);
}

TEST(HidrawDriver, ANodeThatIsNotHidrawIsRefusedOnceWithTheIoctlsReason) {
  FakeSysfs f;
  f.add("hidraw1", "HID_ID=0003:00000483:00005750\n");
  fs::create_directories(f.dev());
  std::ofstream(f.dev() / "hidraw1") << "not a device";
  LogCapture logs;
  HidrawDriverOptions o;
  o.device.usb = UsbId{0x0483, 0x5750};
  o.sysfs_root = f.sys();
  o.dev_root = f.dev();
  o.reconnect_min = 0.01;
  o.reconnect_max = 0.02;
  o.log = logs.sink();
  HidrawDriver d(std::move(o));
  EXPECT_TRUE(run_for(d, 200ms, 2s));
  EXPECT_GE(d.open_failures(), 2u);
  const auto lines = logs.all();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("cannot open: " + (f.dev() / "hidraw1").string() + ": HIDIOCGRDESCSIZE: "), std::string::npos)
      << lines[0];
}

}  // namespace
}  // namespace posefair::drivers
