#pragma once
// The hidraw driver (docs/hid-gpio.md, "HID"): a USB (or Bluetooth, I2C) HID tracker read
// through Linux hidraw, one input report per read(), decoded by a HID report decoder
// (hid_report_decoder.hpp), each sample timed (time_base.hpp) and handed to the sink.
//
// The link (opening with backoff, losses, reconnects, counters, health, the log lines) is
// DeviceLinkDriver's (device_link_driver.hpp), as for the serial driver. Here:
//   - finds the node (a path, or the first /dev/hidrawN in number order whose HID id in sysfs
//     has this vendor:product and, when given, this serial number) and opens it read-only. No
//     such node is "absent"; permissions and the rest are logged as errors.
//   - on each open reads the report descriptor (HIDIOCGRDESCSIZE, HIDIOCGRDESC) and has the
//     protocol's HidDecoderFactory (hid_report_decoder.hpp) build the decoder for it; a device
//     the protocol refuses (hid-sensor: no orientation quaternion in the descriptor) is treated
//     like a device that cannot be opened: logged once, retried with backoff.
//   - polls with a short timeout (read_timeout, 20 ms); each read() is one report, its receive
//     time CLOCK_MONOTONIC taken right after the read.
//   - the device is gone on POLLHUP/POLLERR, a read error EIO/ENODEV/ENXIO, or end of file: it
//     closes the node (and, for hid-sensor, the decoder built for it) and reopens.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/device_link_driver.hpp"
#include "posefair/drivers/hid_report_decoder.hpp"
#include "posefair/core/options.hpp"
#include "posefair/drivers/usb_id.hpp"

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

// stream_id, reconnect_min/max, time_source, time_base, read_timeout, log and name are the
// link's (DeviceLinkOptions); the default name is "hid:<device or usb id>".
struct HidrawDriverOptions : DeviceLinkOptions {
  HidDeviceSpec device;
  std::string protocol = "hid-sensor";  // HID decoder registry name (hid_report_decoder.hpp)
  OptionMap decoder_options;             // its options
  std::filesystem::path sysfs_root = "/sys";  // tests
  std::filesystem::path dev_root = "/dev";    // tests
};

class HidrawDriver final : public DeviceLinkDriver {
 public:
  // Throws std::invalid_argument: no device and no USB id, an unknown protocol, a bad decoder
  // option (OptionError; hid-vendor: HidVendorLayoutError), bad backoff or time base.
  explicit HidrawDriver(HidrawDriverOptions options);
  ~HidrawDriver() override;

  std::uint64_t reports() const { return reports_.load(std::memory_order_relaxed); }  // reads that returned a report
  // decoder_counters() (DeviceLinkDriver) are summed over every decoder this driver used.

 private:
  struct Node;
  std::variant<LinkOpened, LinkOpenFailure> open_link() override;
  LinkRead read_link(int timeout_ms, SampleStamper& stamper) override;
  void close_link() override;
  DecoderCounters link_decoder_counters() const override;

  HidrawDriverOptions options_;
  std::unique_ptr<HidDecoderFactory> decoder_factory_;
  // run()'s thread only: the open node, the counters of the decoders of earlier connections
  // (one is built per open), the read buffer.
  std::unique_ptr<Node> node_;
  DecoderCounters past_;
  std::vector<std::uint8_t> buffer_;
  std::atomic<std::uint64_t> reports_{0};
};

}  // namespace posefair::drivers
