#pragma once
// A device protocol decoder: bytes in, samples out. Pure: no I/O, no clock, no allocation after
// construction, never throws on any input, never reads outside what it was given. The serial
// driver feeds it whatever each read returned (any split of the stream into chunks gives the
// same samples); fuzz targets and golden replays feed it files.
//
// Every decoder resynchronises after garbage (it searches for the next frame start), verifies
// the frame's checksum before using a byte of it, and counts what it saw. One file per
// protocol in drivers/src/, opening with a comment that names the reference document and the
// device's quirks and declaring the options it reads (core/options.hpp) in its DecoderEntry;
// decoder_registry.cpp lists the entries (one line per protocol).
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/core/options.hpp"

namespace posefair::drivers {

// One orientation (and perhaps position) a frame carried, in posefair's convention: a unit
// quaternion (w, x, y, z) rotating sensor coordinates into world coordinates, v_w = q v_s q*.
// Raw inertial readings ride along in the sensor's own axes, converted to SI units (rad/s, m/s²,
// µT), either beside that orientation or alone (kNoOrientation: the orientation is not a
// measurement). Each decoder says in its opening comment how its raw readings attach.
struct DecodedSample {
  Quat orientation = Quat::Identity();
  Vec3 position = Vec3::Zero();
  Vec3 gyro = Vec3::Zero();       // rad/s, valid with kHasGyro
  Vec3 accel = Vec3::Zero();      // m/s², valid with kHasAccel
  Vec3 mag = Vec3::Zero();        // µT, valid with kHasMag
  std::uint32_t flags = 0;        // kHasPosition, kHasDeviceTime, kHasGyro/Accel/Mag, kNoOrientation (core/sample.hpp)
  double device_time = 0.0;       // s, valid with kHasDeviceTime; rollover already unwrapped
  std::uint64_t frame_counter = 0;  // the device's own packet counter, where it sends one (unwrapped)
  bool has_frame_counter = false;
};

// What a decoded sample gives a Sample: its flags (the Sample's kinds only: kHasPosition,
// kHasDeviceTime, the raw readings' and kNoOrientation), orientation, and each value its flags
// declare. Stream id, sequence and times are the stamper's.
inline void fill_sample(const DecodedSample& d, Sample& s) {
  s.flags = d.flags & (kHasPosition | kHasDeviceTime | kHasGyro | kHasAccel | kHasMag | kNoOrientation);
  s.orientation = d.orientation;
  if (s.has_position()) s.position = d.position;
  if ((s.flags & kHasDeviceTime) != 0) s.device_time = d.device_time;
  if (s.has_gyro()) s.gyro = d.gyro;
  if (s.has_accel()) s.accel = d.accel;
  if (s.has_mag()) s.mag = d.mag;
}

struct DecoderCounters {
  std::uint64_t bytes = 0;           // bytes fed
  std::uint64_t frames = 0;          // whole frames whose checksum (or CRC) matched
  std::uint64_t samples = 0;         // samples handed to the sink
  std::uint64_t bad_checksum = 0;    // whole frames whose checksum did not match
  std::uint64_t malformed = 0;       // frames with a valid checksum but impossible contents (bad length field, NaN, zero quaternion)
  std::uint64_t ignored_frames = 0;  // valid frames that give no sample and no raw reading (e.g. WitMotion 0x56 pressure)
  std::uint64_t resyncs = 0;         // times the decoder had to skip bytes to find a frame start
  std::uint64_t skipped_bytes = 0;   // bytes skipped while resynchronising
  friend bool operator==(const DecoderCounters&, const DecoderCounters&) = default;
};

class DecodedSink {
 public:
  virtual ~DecodedSink() = default;
  virtual void on_sample(const DecodedSample& sample) = 0;
};

class Decoder {
 public:
  virtual ~Decoder() = default;
  // The protocol's registry name, e.g. "witmotion".
  virtual std::string_view protocol() const = 0;
  // Consumes every byte of `bytes` (a partial frame at the end is kept for the next call) and
  // hands every sample of every valid frame to sink, in stream order.
  virtual void feed(std::span<const std::uint8_t> bytes, DecodedSink& sink) = 0;
  // Forgets a partial frame and any rollover state (after the device was reopened).
  virtual void reset() = 0;
  const DecoderCounters& counters() const { return counters_; }

 protected:
  // Resynchronisation accounting, the same for every protocol: n bytes skipped while looking
  // for a frame start. A run of skips until the next valid frame (end_resync) is one resync.
  void skip(std::size_t n) {
    if (n == 0) return;
    if (!resyncing_) ++counters_.resyncs;
    resyncing_ = true;
    counters_.skipped_bytes += n;
  }
  void end_resync() { resyncing_ = false; }

  DecoderCounters counters_;

 private:
  bool resyncing_ = false;
};

// A serial protocol as the registry lists it: its name, one line saying what it reads, the
// options it accepts, and the factory, which judges them (OptionError for a bad one).
struct DecoderEntry {
  std::string_view name;
  std::string_view description;
  std::span<const OptionSpec> options;
  std::unique_ptr<Decoder> (*make)(const OptionMap& options);
};

// The registry: every serial protocol, sorted by name.
std::span<const DecoderEntry* const> decoder_entries();
// nullptr for an unknown protocol name.
const DecoderEntry* find_decoder(std::string_view protocol);
// nullptr for an unknown protocol name. Throws OptionError for an option value the protocol does
// not accept.
std::unique_ptr<Decoder> make_decoder(std::string_view protocol, const OptionMap& options = {});
// Every registered protocol name, sorted.
std::vector<std::string> decoder_protocols();

}  // namespace posefair::drivers
