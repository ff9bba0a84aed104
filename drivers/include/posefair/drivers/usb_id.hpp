#pragma once
// A USB vendor:product id, as `usb = "1a86:7523"` names a serial port (serial_port.hpp) or a
// HID device (hidraw_driver.hpp) in the configuration.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace posefair::drivers {

struct UsbId {
  std::uint16_t vid = 0;
  std::uint16_t pid = 0;
  friend bool operator==(const UsbId&, const UsbId&) = default;
};
// "1a86:7523" (hex, 1 to 4 digits each, either case) -> {0x1a86, 0x7523}; nullopt otherwise.
std::optional<UsbId> parse_usb_id(std::string_view text);
std::string to_string(const UsbId& id);  // "1a86:7523"

}  // namespace posefair::drivers
