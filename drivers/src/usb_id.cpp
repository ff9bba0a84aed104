// USB vendor:product ids; see usb_id.hpp.
#include "posefair/drivers/usb_id.hpp"

#include <cstdio>

namespace posefair::drivers {

std::optional<UsbId> parse_usb_id(std::string_view text) {
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos) return std::nullopt;
  auto hex = [](std::string_view s, std::uint16_t& out) {
    if (s.empty() || s.size() > 4) return false;
    unsigned v = 0;
    for (char c : s) {
      unsigned d = 0;
      if (c >= '0' && c <= '9')
        d = static_cast<unsigned>(c - '0');
      else if (c >= 'a' && c <= 'f')
        d = static_cast<unsigned>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F')
        d = static_cast<unsigned>(c - 'A' + 10);
      else
        return false;
      v = v * 16 + d;
    }
    out = static_cast<std::uint16_t>(v);
    return true;
  };
  UsbId id;
  if (!hex(text.substr(0, colon), id.vid) || !hex(text.substr(colon + 1), id.pid)) return std::nullopt;
  return id;
}

std::string to_string(const UsbId& id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04x:%04x", id.vid, id.pid);
  return buf;
}

}  // namespace posefair::drivers
