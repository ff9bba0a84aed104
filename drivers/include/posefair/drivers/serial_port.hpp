#pragma once
// A serial port (docs/devices.md, "Serial"): a small RAII wrapper over libserialport. Opened by
// device path or by USB VID:PID (and serial number), configured (baud, data bits, parity, stop
// bits, flow control), read without blocking: poll() on the port's descriptor wakes the reader,
// so a read waits at most its timeout and a driver sees stop requests between reads.
//
// Paths: symlinks (/dev/serial/by-id/..., a udev alias) are resolved at every open, so a link
// that a replug re-points is followed. libserialport only knows terminals that sysfs describes
// (ttyS, ttyUSB, ttyACM, ...); any other terminal device (a pseudo-terminal made by socat or
// ser2net, or a test's pty) is opened and configured directly with termios, with the same
// settings and the same read semantics.
//
// Errors are values, not exceptions: an open tells "absent" (retry later) from "refused"
// (permissions, busy, settings), a read tells "device gone" (unplugged: EIO, ENXIO, ENODEV, a
// hangup) from a transient failure.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/usb_id.hpp"

struct sp_port;  // libserialport's handle

namespace posefair::drivers {

enum class Parity { None, Odd, Even, Mark, Space };
enum class FlowControl { None, XonXoff, RtsCts, DtrDsr };

struct SerialSettings {
  int baud = 115200;
  int data_bits = 8;  // 5 .. 8
  Parity parity = Parity::None;
  int stop_bits = 1;  // 1 or 2
  FlowControl flow_control = FlowControl::None;
};

// Throws std::invalid_argument naming the bad field (baud ≤ 0, data bits outside 5..8, stop
// bits not 1 or 2).
void validate(const SerialSettings& settings);
// "115200 8N1", "9600 7E2 rtscts".
std::string describe(const SerialSettings& settings);

// Which device to open: a path, or the first USB serial port (in path order) with this
// VID:PID and, when given, this serial number.
struct SerialPortSpec {
  std::string device;          // e.g. "/dev/ttyUSB0", "/dev/serial/by-id/usb-..."; empty with usb
  std::optional<UsbId> usb;    // instead of device
  std::string usb_serial;      // with usb: the USB serial number must match ("" = any)
  // "/dev/ttyUSB0", "usb 1a86:7523", "usb 1a86:7523 serial A50285BI".
  std::string describe() const;
};

enum class SerialErrorKind {
  None,
  NotFound,          // open: no such device (path missing, no USB match): it may appear later
  PermissionDenied,  // open: EACCES/EPERM (dialout group, udev rule)
  Busy,              // open: EBUSY, or held exclusively by another process
  BadSettings,       // open: the device refused the settings (e.g. an unsupported baud rate)
  NotATerminal,      // open: the path is not a terminal device
  DeviceGone,        // read: EIO, ENXIO, ENODEV, a hangup or end of file: unplugged or closed
  Transient,         // read/open: anything else; retrying may help
};
std::string_view to_string(SerialErrorKind kind);

struct SerialError {
  SerialErrorKind kind = SerialErrorKind::None;
  int os_error = 0;     // errno when the OS gave one
  std::string message;  // e.g. "/dev/ttyUSB0: Permission denied"
  explicit operator bool() const { return kind != SerialErrorKind::None; }
};

// One port as the system lists it (libserialport's enumeration, sysfs on Linux).
struct PortInfo {
  std::string path;         // "/dev/ttyUSB0"
  std::string description;  // libserialport's description, e.g. "CP2102 USB to UART Bridge Controller"
  std::string transport;    // "native", "usb", "bluetooth"
  bool has_usb_id = false;
  UsbId usb;
  std::string usb_serial, usb_manufacturer, usb_product;  // "" when the device gives none
};
// Every serial port the system knows, sorted by path. Pseudo-terminals are not listed.
// Throws std::runtime_error when the enumeration itself fails.
std::vector<PortInfo> list_serial_ports();

class SerialPort {
 public:
  struct ReadResult {
    std::size_t bytes = 0;  // 0 with no error: the timeout passed without data
    SerialError error;
  };

  SerialPort() = default;
  ~SerialPort();
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Closes a port already open, then opens and configures the device. On failure the port
  // stays closed and the error says why. Never throws for device problems.
  SerialError open(const SerialPortSpec& spec, const SerialSettings& settings);
  void close();
  bool is_open() const { return fd_ >= 0; }

  // The device node actually opened (symlinks resolved), e.g. "/dev/ttyUSB0".
  const std::string& path() const { return path_; }
  // Something worth one log line about the last open, e.g. that several USB devices matched.
  const std::string& note() const { return note_; }
  // The descriptor reads poll on (-1 when closed).
  int fd() const { return fd_; }

  // Waits up to timeout_ms (0: do not wait) for data, then reads what is there, at most
  // buffer.size() bytes. Interrupted waits return 0 bytes.
  ReadResult read(std::span<std::uint8_t> buffer, int timeout_ms);
  // Writes all of `bytes` (commands to a device, tests), waiting up to timeout_ms in total.
  SerialError write(std::span<const std::uint8_t> bytes, int timeout_ms);

 private:
  SerialError open_path(const std::string& device, const SerialSettings& settings);
  SerialError open_with_termios(const std::string& node, const SerialSettings& settings);

  ::sp_port* port_ = nullptr;  // libserialport's handle; null for a termios-opened device
  int fd_ = -1;
  std::string path_;
  std::string note_;
};

}  // namespace posefair::drivers
