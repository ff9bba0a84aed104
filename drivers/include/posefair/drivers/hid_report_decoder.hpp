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
#include <cstdint>
#include <span>
#include <string_view>

#include "posefair/drivers/decoder.hpp"

namespace posefair::drivers {

class HidReportDecoder {
 public:
  virtual ~HidReportDecoder() = default;
  // "hid-sensor" or "hid-vendor".
  virtual std::string_view protocol() const = 0;
  // One whole input report as hidraw returned it.
  virtual void decode(std::span<const std::uint8_t> report, DecodedSink& sink) = 0;
  // Forgets rollover state (after the device was reopened).
  virtual void reset() = 0;
  const DecoderCounters& counters() const { return counters_; }

 protected:
  DecoderCounters counters_;
};

}  // namespace posefair::drivers
