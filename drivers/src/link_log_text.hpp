#pragma once
// The few words the link log lines share ("waited 3.0 s", "backoff 0.1 s .. 5 s", "12
// attempts"), so that the device links (device_link_driver.cpp) and the GPIO lines read alike.
// Private to drivers/src.
#include <cstdint>
#include <cstdio>
#include <string>

namespace posefair::drivers {

inline std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

inline std::string backoff_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", s);
  return buf;
}

inline std::string attempts_text(std::uint64_t n) { return std::to_string(n) + (n == 1 ? " attempt" : " attempts"); }

}  // namespace posefair::drivers
