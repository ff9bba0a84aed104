#pragma once
// A decoder of HID input reports: one report in, at most one sample out. The hidraw driver
// hands it each read() (hidraw returns exactly one report per read, starting with the report ID
// byte when the device's descriptor uses report IDs). Unlike the serial decoders (decoder.hpp)
// there is no byte stream to resynchronise: report boundaries come from the kernel. Pure: no
// I/O, no clock, no allocation after construction, never throws on any report, never reads
// outside it.
//
// Counters (DecoderCounters, reused so the daemon reports HID streams like serial ones):
// bytes = bytes of all reports given; frames = reports of the decoder's report ID and of a usable
// length; samples; malformed = reports of the right ID that are too short, or whose values are
// out of the logical range, not finite, or not a unit quaternion within tolerance;
// ignored_frames = reports of other IDs (other sensors of a sensor hub, feature echoes).
// bad_checksum, resyncs and skipped_bytes stay 0.
//
// A HID protocol is registered like the serial and CAN ones (one file per protocol declaring
// its options and its HidDecoderEntry, one line in hid_decoder_registry.cpp). Its entry does
// not build a decoder directly: a HID device describes its reports in its report descriptor,
// which is known only once the device is open, so the entry judges the options and returns a
// HidDecoderFactory that the hidraw driver asks for a decoder on every open.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/decoder.hpp"
#include "posefair/core/options.hpp"

namespace posefair::drivers {

class HidReportDecoder {
 public:
  virtual ~HidReportDecoder() = default;
  // The protocol's registry name, e.g. "hid-sensor".
  virtual std::string_view protocol() const = 0;
  // One whole input report as hidraw returned it.
  virtual void decode(std::span<const std::uint8_t> report, DecodedSink& sink) = 0;
  // Forgets rollover state (after the device was reopened).
  virtual void reset() = 0;
  const DecoderCounters& counters() const { return counters_; }

 protected:
  DecoderCounters counters_;
};

// A HID protocol with its options judged: makes the decoder for each device opened.
class HidDecoderFactory {
 public:
  virtual ~HidDecoderFactory() = default;
  // The decoder for a device whose report descriptor is `descriptor` (as HIDIOCGRDESC returns
  // it), and in `what` a few words about the report it reads, for the driver's "opened" line.
  // Throws std::invalid_argument when the device does not fit (say, no orientation in its
  // descriptor): the driver logs the message and retries like a failed open.
  virtual std::unique_ptr<HidReportDecoder> make(std::span<const std::uint8_t> descriptor, std::string& what) const = 0;
};

// A HID protocol as the registry lists it: its name, one line saying what it reads, the options
// it accepts, and `configure`, which judges them (OptionError for a bad one).
struct HidDecoderEntry {
  std::string_view name;
  std::string_view description;
  std::span<const OptionSpec> options;
  std::unique_ptr<HidDecoderFactory> (*configure)(const OptionMap& options);
};

// The registry: every HID protocol, sorted by name.
std::span<const HidDecoderEntry* const> hid_decoder_entries();
// nullptr for an unknown protocol name.
const HidDecoderEntry* find_hid_decoder(std::string_view protocol);
// nullptr for an unknown protocol name. Throws OptionError for an option value the protocol does
// not accept.
std::unique_ptr<HidDecoderFactory> configure_hid_decoder(std::string_view protocol, const OptionMap& options = {});
// Every registered HID protocol name, sorted.
std::vector<std::string> hid_decoder_protocols();

}  // namespace posefair::drivers
