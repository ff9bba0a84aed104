#pragma once
// The hidraw driver (docs/hid-gpio.md, "HID"): a USB (or Bluetooth, I2C) HID tracker read
// through Linux hidraw, one input report per read(), decoded by a HID report decoder
// (hid_report_decoder.hpp), each sample timed (time_base.hpp) and handed to the sink.
//
// run() follows the serial driver (serial_driver.hpp):
//   - finds the node (a path, or the first /dev/hidrawN in number order whose HID id in sysfs
//     has this vendor:product and, when given, this serial number) and opens it read-only.
//     While it is absent or refuses, it retries with exponential backoff (reconnect_min,
//     doubling, up to reconnect_max).
//   - on each open reads the report descriptor (HIDIOCGRDESCSIZE, HIDIOCGRDESC) and has the
//     protocol's HidDecoderFactory (hid_report_decoder.hpp) build the decoder for it; a device
//     the protocol refuses (hid-sensor: no orientation quaternion in the descriptor) is treated
//     like a device that cannot be opened: logged once, retried with backoff.
//   - polls with a short timeout (read_timeout, 20 ms), so a stop request is seen within it;
//     each read() is one report, its receive time CLOCK_MONOTONIC taken right after the read.
//   - when the device goes away (POLLHUP/POLLERR, read error EIO/ENODEV/ENXIO, end of file)
//     it closes the node, counts an outage, resets the decoder and the time base, and reopens
//     with the same backoff.
//   - logs each state change once: opened, lost, reopened, a changed reason for not opening.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/device_options.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"
#include "posefair/drivers/serial_driver.hpp"  // LogLevel, DriverLog
#include "posefair/drivers/serial_port.hpp"    // UsbId, parse_usb_id
#include "posefair/drivers/time_base.hpp"

namespace posefair::drivers {

// What the kernel says about a HID device in /sys/class/hidraw/hidrawN/device/uevent:
// HID_ID=<bus>:<vendor>:<product> (hex: 4, 8 and 8 digits), HID_NAME, HID_UNIQ (the USB serial
// number, a Bluetooth address, or empty).
struct HidUevent {
  std::uint16_t bus = 0;  // 0x0003 USB, 0x0005 Bluetooth, 0x0018 I2C
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::string name;
  std::string uniq;
};
// nullopt when the text has no well-formed HID_ID line. Pure.
std::optional<HidUevent> parse_hid_uevent(std::string_view text);

// Which device to open: a path, or a HID id (USB VID:PID; the same numbers for other buses).
struct HidDeviceSpec {
  std::string device;        // e.g. "/dev/hidraw3"; empty with usb
  std::optional<UsbId> usb;  // instead of device
  std::string serial;        // with usb: HID_UNIQ must match ("" = any)
  // "/dev/hidraw3", "usb 0483:5750", "usb 0483:5750 serial 2053386B5650".
  std::string describe() const;
};

// Every /dev/hidrawN (as `dev_root`/hidrawN) whose <sysfs_root>/class/hidraw/hidrawN/device/uevent
// matches spec.usb and spec.serial, in N order. Empty when nothing matches or sysfs is absent.
std::vector<std::string> find_hidraw_nodes(const HidDeviceSpec& spec, const std::filesystem::path& sysfs_root = "/sys",
                                           const std::filesystem::path& dev_root = "/dev");

struct HidrawDriverOptions {
  HidDeviceSpec device;
  std::string protocol = "hid-sensor";  // HID decoder registry name (hid_report_decoder.hpp)
  OptionMap decoder_options;             // its options
  std::uint32_t stream_id = 0;
  double reconnect_min = 0.1;  // s: the first wait after a failed open; finite, > 0
  double reconnect_max = 5.0;  // s: waits double up to this; >= reconnect_min
  TimeSource time_source = TimeSource::Auto;
  TimeBaseOptions time_base;
  double read_timeout = 0.02;  // s: poll timeout, in (0, 0.05]
  std::filesystem::path sysfs_root = "/sys";  // tests
  std::filesystem::path dev_root = "/dev";    // tests
  DriverLog log;     // may be empty; called from run()'s thread
  std::string name;  // for logs; default "hid:<device or usb id>"
};

class HidrawDriver final : public Driver {
 public:
  // Throws std::invalid_argument: no device and no USB id, an unknown protocol, a bad decoder
  // option (OptionError; hid-vendor: HidVendorLayoutError), bad backoff or time base.
  explicit HidrawDriver(HidrawDriverOptions options);

  std::string_view name() const override { return name_; }
  // Runs until stop is requested; a lost device is waited for. Returns within about
  // read_timeout of the request.
  void run(std::stop_token stop, SampleSink& sink) override;

  std::uint64_t reports() const { return reports_.load(std::memory_order_relaxed); }  // reads that returned a report
  std::uint64_t samples() const { return samples_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  std::uint64_t outages() const { return outages_.load(std::memory_order_relaxed); }
  std::uint64_t reconnects() const { return reconnects_.load(std::memory_order_relaxed); }
  std::uint64_t open_failures() const { return open_failures_.load(std::memory_order_relaxed); }
  std::uint64_t read_errors() const { return read_errors_.load(std::memory_order_relaxed); }
  bool connected() const { return connected_.load(std::memory_order_acquire); }
  DecoderCounters decoder_counters() const;  // summed over every decoder this run() used
  std::string device_path() const;           // the node opened last
  std::optional<DeviceHealth> health() const override;

 private:
  struct Opened;
  void log(LogLevel level, const std::string& message) const;

  HidrawDriverOptions options_;
  std::string name_;
  std::unique_ptr<HidDecoderFactory> decoder_factory_;

  std::atomic<std::uint64_t> reports_{0}, samples_{0}, dropped_{0}, outages_{0}, reconnects_{0}, open_failures_{0},
      read_errors_{0}, fallbacks_{0};
  std::atomic<bool> connected_{false}, trusted_{false};
  mutable std::mutex snapshot_mutex_;
  DecoderCounters decoder_snapshot_;
  std::string device_path_;
};

}  // namespace posefair::drivers
