#pragma once
// An output encoding: how the publisher turns one pose message into one UDP datagram
// ([[output]] encoding = "<name>", docs/protocol.md). Each encoding lives with its format (the
// binary v1 encoder in wire_protocol.cpp, JSON lines in json_lines.cpp), declares the
// [[output]] keys it reads in its OutputEncoderEntry (core/options.hpp, the same
// convention as the device decoders) and is registered by one line in
// output_encoder_registry.cpp. An output's encoder is built once, when the config is loaded;
// the publisher calls it through this interface and knows no encoding by name.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "posefair/daemon/wire_protocol.hpp"
#include "posefair/core/options.hpp"

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
  // An encoding with a transport of its own (DDS) publishes each pose itself: the publisher
  // calls deliver() instead of encode() and sending, and counts a false as a failed send.
  virtual bool delivers() const { return false; }
  virtual bool deliver(const PoseMessage&) const { return false; }
};

// A stream an output carries, as its encoding may need it: a client names poses by a bone, a
// tracker number or a topic rather than by posefair's stream id. The name is the [[stream]]
// name; an encoder copies what it keeps.
struct OutputStream {
  std::uint32_t id = 0;
  std::string_view name;
};

// An encoding as the registry lists it: its name, one line saying what it writes, the
// [[output]] keys it accepts beyond the common ones, and the factory, which reads them with
// posefair::OptionReader and judges them (posefair::OptionError, naming the key, for a bad one).
// The factory also gets the streams the output carries, in the order of its `streams` key (every
// stream in config order when that is not given), for options that name one value per stream.
// An encoding without options may hand out one shared instance: outputs that share an encoder
// object share its datagram (the publisher encodes each pose once per encoder).
struct OutputEncoderEntry {
  std::string_view name;
  std::string_view description;
  std::span<const posefair::OptionSpec> options;
  std::shared_ptr<const OutputEncoder> (*make)(const posefair::OptionMap& options, std::span<const OutputStream> streams);
  // The UDP port a destination without one gets (the client's usual port); 0: posefair's 5700.
  std::uint16_t default_port = 0;
  // The encoder delivers poses itself (OutputEncoder::delivers): the output has no destinations.
  bool own_transport = false;
};

// Every registered encoding, in registration order; the first is the default.
std::span<const OutputEncoderEntry* const> output_encoder_entries();
// The encoding registered under name, nullptr when none is.
const OutputEncoderEntry* find_output_encoder(std::string_view name);
// Their names, in registration order (for an error listing them).
std::vector<std::string_view> output_encoder_names();
// The default encoding with its default options (an [[output]] without `encoding`).
std::shared_ptr<const OutputEncoder> default_output_encoder();

}  // namespace posefair::daemon
