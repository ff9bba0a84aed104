#pragma once
// Bytes written in hex in a test ("FF 7F 00"), for the decoder tests and the candump log tests.
// No test framework and no library behind it, so any test can include it.
#include <cstdint>
#include <string_view>
#include <vector>

namespace posefair::testing {

// The bytes written in hex digits; any other character (spaces) is skipped.
inline std::vector<std::uint8_t> hex(std::string_view text) {
  std::vector<std::uint8_t> out;
  int hi = -1;
  for (const char c : text) {
    int v = -1;
    if (c >= '0' && c <= '9') v = c - '0';
    if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
    if (c >= 'A' && c <= 'F') v = c - 'A' + 10;
    if (v < 0) continue;
    if (hi < 0) {
      hi = v;
    } else {
      out.push_back(static_cast<std::uint8_t>(hi << 4 | v));
      hi = -1;
    }
  }
  return out;
}

}  // namespace posefair::testing
