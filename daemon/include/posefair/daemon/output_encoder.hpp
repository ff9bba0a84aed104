#pragma once
// An output encoding: how the publisher turns one pose message into one UDP datagram
// ([[output]] encoding = "<name>", docs/protocol.md). Each encoding lives with its format (the
// binary v1 encoder in wire_protocol.cpp, JSON lines in json_lines.cpp) and is registered by
// one line in output_encoder_registry.cpp. An output's encoder is chosen once, when the config
// is loaded; the publisher calls it through this interface and knows no encoding by name.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::daemon {

class OutputEncoder {
 public:
  virtual ~OutputEncoder() = default;
  // The registry name, the value of [[output]] encoding, e.g. "binary".
  virtual std::string_view name() const = 0;
  // Writes m's datagram into out (kMaxDatagramSize bytes) and returns its size. Runs on the
  // publisher thread for every pose: an encoding meant for the real-time path must not
  // allocate (binary does not; JSON lines, a convenience, does).
  virtual std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const = 0;
  // [[output]] keys this encoding accepts beyond the common ones (none for binary and JSON).
  virtual std::span<const std::string_view> config_keys() const { return {}; }
};

// Every registered encoding, in registration order; the first is the default.
std::span<const OutputEncoder* const> output_encoders();
// The encoding registered under name, nullptr when none is.
const OutputEncoder* find_output_encoder(std::string_view name);
// Their names, in registration order (for an error listing them).
std::vector<std::string_view> output_encoder_names();

}  // namespace posefair::daemon
