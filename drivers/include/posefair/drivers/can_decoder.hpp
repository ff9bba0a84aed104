#pragma once
// A CAN device protocol decoder: frames in, samples out. The CAN counterpart of decoder.hpp:
// the same DecodedSample, DecodedSink and DecoderCounters, but fed one whole frame at a time
// (a CAN controller delivers frames, never a byte stream, so there is nothing to resynchronise
// within a frame; what can go wrong is lost, repeated or foreign frames, and for multi-frame
// protocols a transfer left incomplete). Pure like the serial decoders: no I/O, no clock (time
// comes with the frame), no allocation after construction, never throws on any frame.
//
// One file per protocol in drivers/src/, opening with a comment that names its reference
// document and quirks and declaring the options it reads (core/options.hpp) in its
// CanDecoderEntry; can_decoder_registry.cpp lists the entries (one line per protocol).
//
// Counters. DecoderCounters keeps its meaning per valid protocol message:
//   bytes          payload bytes of the data frames addressed to this decoder (ids it reads)
//   frames         valid messages: a frame whose length and contents passed the checks, or a
//                  multi-frame transfer whose CRC matched (each decoder says which)
//   samples        samples handed to the sink
//   bad_checksum   multi-frame transfers whose CRC did not match
//   malformed      addressed frames or transfers with a wrong length or impossible contents
//   ignored_frames valid messages without an orientation or a raw reading (status, or a time left unused)
//   resyncs        partial sets or transfers given up (lost frames, the sequence moved on)
//   skipped_bytes  payload bytes that went into no valid message (malformed frames, parts of
//                  given-up sets or transfers, stray continuation frames)
// and CanFrameCounters counts the frames themselves, including those not addressed here.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/decoder.hpp"
#include "posefair/formats/can_frame.hpp"

namespace posefair::drivers {

// The frame value lives in formats (candump logs hold frames too); the decoders name it as theirs.
using formats::CanFrame;
using formats::valid_fd_length;

// A kernel receive filter, as struct can_filter (linux/can.h): a frame passes when
// (frame.can_id & mask) == (id & mask). id and mask include the canid_t flags, so a filter can
// ask for extended frames only and refuse remote frames.
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  bool matches(std::uint32_t can_id) const { return (can_id & mask) == (id & mask); }
  friend bool operator==(const CanFilter&, const CanFilter&) = default;
};

struct CanFrameCounters {
  std::uint64_t received = 0;  // every frame fed
  std::uint64_t foreign = 0;   // data frames with an identifier this decoder does not read
  std::uint64_t remote = 0;    // remote (RTR) frames
  std::uint64_t errors = 0;    // error frames (kErrFlag); the driver logs their classes
  friend bool operator==(const CanFrameCounters&, const CanFrameCounters&) = default;
};

class CanDecoder {
 public:
  virtual ~CanDecoder() = default;
  // The protocol's registry name, e.g. "xsens-can".
  virtual std::string_view protocol() const = 0;
  // The kernel filters that pass every frame this decoder reads (and as few others as they
  // can); the SocketCAN driver sets them with CAN_RAW_FILTER. Error frames are asked for
  // separately (CAN_RAW_ERR_FILTER).
  virtual std::vector<CanFilter> filters() const = 0;

  // One frame, in bus order. Error and remote frames and frames with identifiers this decoder
  // does not read are counted and otherwise ignored; the rest are decoded, and every sample
  // they complete goes to sink.
  void feed(const CanFrame& frame, DecodedSink& sink) {
    ++frame_counters_.received;
    if (frame.error()) {
      ++frame_counters_.errors;
    } else if (frame.remote()) {
      ++frame_counters_.remote;
    } else if (!reads(frame)) {
      ++frame_counters_.foreign;
    } else {
      counters_.bytes += frame.len;
      decode(frame, sink);
    }
  }
  // Forgets partial sets and transfers and any rollover state (after the bus was reopened).
  virtual void reset() = 0;

  const DecoderCounters& counters() const { return counters_; }
  const CanFrameCounters& frame_counters() const { return frame_counters_; }

 protected:
  // Whether `frame` (a data frame) carries an identifier this decoder reads.
  virtual bool reads(const CanFrame& frame) const = 0;
  // Decodes a data frame that reads() accepted.
  virtual void decode(const CanFrame& frame, DecodedSink& sink) = 0;

  DecoderCounters counters_;
  CanFrameCounters frame_counters_;
};

// A CAN protocol as the registry lists it: its name, one line saying what it reads, the
// options it accepts, and the factory, which judges them (OptionError for a bad one).
struct CanDecoderEntry {
  std::string_view name;
  std::string_view description;
  std::span<const OptionSpec> options;
  std::unique_ptr<CanDecoder> (*make)(const OptionMap& options);
};

// The registry: every CAN protocol, sorted by name.
std::span<const CanDecoderEntry* const> can_decoder_entries();
// nullptr for an unknown protocol name.
const CanDecoderEntry* find_can_decoder(std::string_view protocol);
// nullptr for an unknown protocol name. Throws OptionError for an option value the protocol does
// not accept.
std::unique_ptr<CanDecoder> make_can_decoder(std::string_view protocol, const OptionMap& options = {});
// Every registered CAN protocol name, sorted.
std::vector<std::string> can_decoder_protocols();

// Reads an identifier option: decimal or 0x hex, at most `max`. Throws OptionError naming
// `option` otherwise.
std::uint32_t parse_can_id_option(std::string_view option, std::string_view text, std::uint32_t max);
// Reads an id format option, "standard" or "extended" (true). Throws as above.
bool parse_can_id_format_option(std::string_view option, std::string_view text);

}  // namespace posefair::drivers
