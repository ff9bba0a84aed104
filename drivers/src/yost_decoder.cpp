// Yost Labs 3-Space sensors (USB, Embedded, Wireless in wired mode, Bluetooth, Data-logging,
// Nano; firmware 2.x binary protocol), registry name "yost".
//
// Reference documents (facts only; no code taken from them):
//  - "3-Space Sensor Family User Manual", Yost Labs (yostlabs.com/wp/wp-content/uploads/pdf/
//    3-Space-Sensor-Family-User-Manual.pdf), and the per-model manuals (e.g. "3-Space Sensor
//    Nano User's Manual", ©2007-2017). Their text could not be retrieved here; the facts below
//    were taken from Yost Labs' own host libraries, which implement that manual:
//  - Yost's Python API threespace_api.py: command table (0x00 getTaredOrientationAsQuaternion
//    answers 16 bytes '>4f'; 0xDD _setWiredResponseHeaderBitfield takes '>I'; 0x55/0x56
//    start/stop streaming; 0x50/0x52 streaming slots/timing), _generateProtocolHeader (the bits
//    0x01 success/failure '?', 0x02 timestamp 'I', 0x04 command echo 'B', 0x08 checksum 'B',
//    0x10 logical ID 'B', 0x20 serial number 'I', 0x40 data length 'B', packed big-endian in
//    that order), and its read loop (a streamed packet is one whose command echo is 0xFF).
//  - Yost's C++ API (threespace_device.cpp, threespace_sensor.cpp): the same field order, a
//    non-zero success byte means failure, the timestamp and serial number are byte-swapped from
//    big-endian; for streaming it always enables checksum and data length.
//  - Yost's C API for the newer 3-Space firmware (tss/api): the header checksum is validated as
//    the 8-bit sum of the data bytes, and the length is checked against the expected size
//    "to prevent ... when a lot of zeroes are sent causing a data_len of 0 and checksum of 0".
//    (That firmware's header is laid out differently — little-endian, 2-byte length — and is not
//    what this decoder reads.)
//  - Yost's yost_math.hpp: quaternions are stored x, y, z, w (QUAT_X 0 ... QUAT_W 3), matching
//    the wire order of command 0x00.
//
// Packet (device → host, one per streaming interval, wired binary protocol with the response
// header, i.e. streaming started with the 0xF9 start byte or header bits set):
//   [0x01: failure u8][0x02: timestamp u32 BE, µs][0x04: echo u8 = 0xFF][0x08: checksum u8]
//   [0x10: logical id u8][0x20: serial u32 BE][0x40: data length u8]  data: x y z w (f32 BE) ...
// each header field present only if its bit is set (command 221, 4-byte big-endian bitfield).
//
// Choices.
//  - Framing. Header-less streaming is 16 bytes of floats with no sync, no length and no check;
//    it is NOT offered. A unit-norm test cannot frame it: shifted by 4, 8 or 12 bytes a stream
//    of (x, y, z, w) reads as (y, z, w, x'), (z, w, x', y'), ... which are unit quaternions too
//    whenever consecutive samples are close (any slow motion), and continuity cannot tell them
//    apart either (the permuted sequence is as smooth as the real one). So the response header
//    is required, with at least success (0x01), checksum (0x08) and data length (0x40); the
//    default 0x4F adds the timestamp (0x02) and command echo (0x04). A packet is recognised at
//    any byte offset where: data length == yost_data_length, command echo == 0xFF (if present),
//    and the checksum == sum of the data bytes mod 256. For random bytes with the default header
//    that is a false match of 2⁻²⁴ per offset (the checksum alone is 2⁻⁸); the success byte and
//    the unit-norm test below then make a false sample rarer still.
//  - Counting. A candidate whose length (and echo) fit but whose checksum does not counts as
//    bad_checksum; without a sync byte the decoder cannot be sure the header was real, so it
//    then advances by one byte (not by a packet), and those bytes count in skipped_bytes with the
//    rest of the resync. A packet with a valid checksum is a frame; with a non-zero success byte
//    (the device reports failure) it is counted as ignored_frames; with a non-finite quaternion or
//    a norm more than 1e-3 away from 1 as malformed; otherwise it gives one sample (normalised).
//    Responses to commands sent while streaming (echo ≠ 0xFF, other lengths) are skipped as
//    garbage: do not talk to the sensor through another program while posefair streams from it.
//  - Timestamp: u32 microseconds of the sensor's clock, rolling over every 2³² µs ≈ 71.6 min.
//    It is unwrapped when a value in the lowest quarter of the range follows one in the highest
//    quarter (gaps up to ~17.9 min between packets unwrap correctly); any other backward step
//    (the clock was set with command 95, or the sensor reset) is passed on as it is.
//    device_time = unwrapped µs · 1e-6 s, with kHasDeviceTime. reset() forgets the rollover.
//  - yost_data_length > 16 allows further streaming slots after slot 0 (which must be command
//    0x00); their bytes are covered by the checksum and otherwise skipped.
//  - Raw readings (issue 17): yost_slots names the streaming slots (command 80) in order; of the
//    slots after the quaternion these are read, their sizes and units from Yost's Python API
//    (command table: 0x25 '>9f', 0x26..0x28 '>fff') and its docstrings ("the gyro vector is in
//    units of radians/sec, the accelerometer vector is in units of G, and the compass vector is
//    in units of gauss"; the accelerometer "will include the static component of acceleration
//    due to gravity"):
//      0x25 getAllCorrectedComponentSensorData  gyro rad/s, accel g, compass gauss (9 f32 BE)
//      0x26 getCorrectedGyroRate                gyro rad/s (3 f32 BE)
//      0x27 getCorrectedAccelerometerVector     accel g
//      0x28 getCorrectedCompassVector           compass gauss
//    -> gyro (kHasGyro), accel · 9.80665 m/s² (kHasAccel), compass · 100 µT (kHasMag), in the
//    sensor's axes (those of command 116, like the quaternion). Not read: the "raw" commands
//    0x40..0x43 (counts "dependent on the currently selected range", not a physical unit) and
//    the "normalized" 0x20..0x23 (unit vectors: the accelerometer's magnitude is gone). A slot
//    after an unknown command (its size is unknown to the decoder) cannot be read: refused. A
//    packet whose readings are not finite counts as malformed.
//
// Conventions. posefair's sample q rotates sensor coordinates into world coordinates. The
// decoder takes the four floats as x, y, z, w and passes the quaternion on unchanged (no
// conjugate): q = (w, x, y, z). The sensor and world axes are the device's own (its axis
// directions, command 116, and its tare), which Yost's default does not make right-handed
// z-up/NED; OPEN: no retrieved Yost text states whether the tared quaternion maps sensor to
// global or global to sensor, so this must be checked once on hardware (docs/devices.md says
// how). Encoder and decoder agree by construction; the tests check the byte layout against
// hand-written packets, not against a vendor example (none was found).
#include "posefair/drivers/yost_decoder.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/checksums.hpp"

namespace posefair::drivers {

namespace {

constexpr double kUnitTolerance = 1e-3;
constexpr std::size_t kQuaternionBytes = 16;
constexpr std::size_t kMaxHeader = 1 + 4 + 1 + 1 + 1 + 4 + 1;
constexpr std::size_t kMaxPacket = kMaxHeader + 255;
constexpr std::uint32_t kRequiredBits = kYostSuccess | kYostChecksum | kYostDataLength;
constexpr std::uint32_t kAllBits = 0x7F;
constexpr double kStandardGravity = 9.80665;  // m/s² per g
constexpr double kMicroteslaPerGauss = 100.0;
constexpr std::size_t kMaxSlots = 8;  // command 80 takes eight slot bytes
constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// A streaming slot command the decoder can read, and what its data holds.
struct SlotCommand {
  std::uint8_t command;
  std::size_t bytes;
  bool gyro, accel, mag;  // in this order
};
constexpr SlotCommand kSlotCommands[] = {
    {0x00, kQuaternionBytes, false, false, false},  // getTaredOrientationAsQuaternion
    {0x25, 36, true, true, true},                   // getAllCorrectedComponentSensorData
    {0x26, 12, true, false, false},                 // getCorrectedGyroRate
    {0x27, 12, false, true, false},                 // getCorrectedAccelerometerVector
    {0x28, 12, false, false, true},                 // getCorrectedCompassVector
};

// Where each raw reading sits in a packet's data (kNone: not streamed), and the data bytes the
// slots take.
struct SlotLayout {
  std::size_t gyro = kNone, accel = kNone, mag = kNone;
  std::size_t bytes = kQuaternionBytes;
};

struct Layout {
  std::size_t success = 0, timestamp = 0, echo = 0, checksum = 0, logical_id = 0, serial_number = 0, length = 0;
  std::size_t header_size = 0;
  bool has_timestamp = false, has_echo = false;
};

Layout layout_of(std::uint32_t bits) {
  Layout l;
  std::size_t at = 0;
  const auto field = [&](std::uint32_t bit, std::size_t size) {
    const std::size_t here = at;
    if ((bits & bit) != 0) at += size;
    return here;
  };
  l.success = field(kYostSuccess, 1);
  l.timestamp = field(kYostTimestamp, 4);
  l.echo = field(kYostCommandEcho, 1);
  l.checksum = field(kYostChecksum, 1);
  l.logical_id = field(kYostLogicalId, 1);
  l.serial_number = field(kYostSerialNumber, 4);
  l.length = field(kYostDataLength, 1);
  l.header_size = at;
  l.has_timestamp = (bits & kYostTimestamp) != 0;
  l.has_echo = (bits & kYostCommandEcho) != 0;
  return l;
}

// A whole number, decimal or 0x-hexadecimal.
bool parse_unsigned(std::string_view s, std::uint32_t& out) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);
    base = 16;
  }
  if (s.empty()) return false;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out, base);
  return ec == std::errc() && ptr == s.data() + s.size();
}

// yost_slots: slot commands separated by commas, e.g. "0x00,0x25"; throws OptionError.
SlotLayout parse_slots(const std::string& text) {
  const auto refuse = [&](const std::string& why) {
    throw OptionError("yost_slots", why + " (a list of the streaming slot commands, e.g. \"0x00,0x25\"; readable after "
                                          "0x00: 0x25, 0x26, 0x27, 0x28), got \"" + text + "\"");
  };
  SlotLayout out;
  out.bytes = 0;
  std::size_t count = 0;
  std::string_view rest = text;
  while (true) {
    const std::size_t comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    std::uint32_t command = 0;
    if (!parse_unsigned(item, command)) refuse("not a command number: \"" + std::string(item) + "\"");
    if (++count > kMaxSlots) refuse("more than 8 slots");
    if (count == 1 && command != 0x00) refuse("slot 0 must be the tared quaternion, 0x00");
    const SlotCommand* known = nullptr;
    for (const SlotCommand& c : kSlotCommands)
      if (c.command == command && (count == 1 || command != 0x00)) known = &c;
    if (known == nullptr) refuse("slot " + std::to_string(count - 1) + ": command " + std::string(item) + " cannot be read");
    std::size_t at = out.bytes;
    for (auto [wanted, slot] : {std::pair{known->gyro, &out.gyro}, std::pair{known->accel, &out.accel},
                                std::pair{known->mag, &out.mag}}) {
      if (!wanted) continue;
      if (*slot != kNone) refuse("slot " + std::to_string(count - 1) + " repeats a reading an earlier slot gives");
      *slot = at;
      at += 12;
    }
    out.bytes += known->bytes;
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  return out;
}

class YostDecoder final : public Decoder {
 public:
  YostDecoder(std::uint32_t bits, std::size_t data_length, const SlotLayout& slots)
      : l_(layout_of(bits)), data_length_(data_length), packet_size_(l_.header_size + data_length), slots_(slots) {}

  std::string_view protocol() const override { return "yost"; }

  void feed(std::span<const std::uint8_t> bytes, DecodedSink& sink) override {
    counters_.bytes += bytes.size();
    const std::uint8_t* in = bytes.data();
    const std::size_t n = bytes.size();
    std::size_t i = 0;
    if (pending_ > 0) {
      // Candidates starting in the kept tail need up to packet_size_ - 1 bytes of the new input.
      const std::size_t k = std::min(n, packet_size_ - 1);
      if (k > 0) std::memcpy(work_.data() + pending_, in, k);
      const std::size_t total = pending_ + k;
      const std::size_t o = scan(work_.data(), total, 0, pending_, sink);
      if (o < pending_) {  // still short of a whole candidate: then all of the input was copied
        std::memmove(work_.data(), work_.data() + o, total - o);
        pending_ = total - o;
        return;
      }
      i = o - pending_;
      pending_ = 0;
    }
    const std::size_t o = scan(in, n, i, n, sink);
    pending_ = n - o;  // < packet_size_
    if (pending_ > 0) std::memcpy(work_.data(), in + o, pending_);
  }

  void reset() override {
    skip(pending_);
    pending_ = 0;
    end_resync();
    have_timestamp_ = false;
    epoch_ = 0;
  }

 private:
  // Tries every candidate start o in [from, limit) that has a whole packet within data[0, total);
  // returns where it stopped (>= limit, or the first start short of a whole packet).
  std::size_t scan(const std::uint8_t* data, std::size_t total, std::size_t from, std::size_t limit,
                   DecodedSink& sink) {
    std::size_t o = from;
    while (o < limit && total - o >= packet_size_) {
      if (try_packet(data + o, sink)) {
        end_resync();
        o += packet_size_;
        continue;
      }
      // Not a packet at o: the next start worth trying is one whose length byte fits.
      const std::size_t last = std::min(limit, total - packet_size_ + 1);  // candidates with a whole packet
      std::size_t next = last;
      if (o + 1 < last) {
        const void* hit = std::memchr(data + o + 1 + l_.length, static_cast<int>(data_length_), last - (o + 1));
        if (hit != nullptr) next = static_cast<std::size_t>(static_cast<const std::uint8_t*>(hit) - data) - l_.length;
      }
      skip(next - o);
      o = next;
    }
    return o;
  }

  // Whether a packet (of any outcome) starts at p; counts what it found.
  bool try_packet(const std::uint8_t* p, DecodedSink& sink) {
    if (p[l_.length] != data_length_) return false;
    if (l_.has_echo && p[l_.echo] != 0xFF) return false;
    const std::uint8_t* data = p + l_.header_size;
    if (checksum::sum8({data, data_length_}) != p[l_.checksum]) {
      ++counters_.bad_checksum;
      return false;
    }
    ++counters_.frames;
    if (p[l_.success] != 0) {
      ++counters_.ignored_frames;
      return true;
    }
    Quat q(bytes::be_f32(data + 12), bytes::be_f32(data), bytes::be_f32(data + 4), bytes::be_f32(data + 8));
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= kUnitTolerance)) {  // also NaN and infinities
      ++counters_.malformed;
      return true;
    }
    q.coeffs() /= norm;
    DecodedSample sample;
    sample.orientation = q;
    if (!read_vector(data, slots_.gyro, 1.0, kHasGyro, sample.gyro, sample.flags) ||
        !read_vector(data, slots_.accel, kStandardGravity, kHasAccel, sample.accel, sample.flags) ||
        !read_vector(data, slots_.mag, kMicroteslaPerGauss, kHasMag, sample.mag, sample.flags)) {
      ++counters_.malformed;
      return true;
    }
    if (l_.has_timestamp) {
      sample.device_time = static_cast<double>(unwrap(bytes::be_u32(p + l_.timestamp))) * 1e-6;
      sample.flags |= kHasDeviceTime;
    }
    ++counters_.samples;
    sink.on_sample(sample);
    return true;
  }

  // Three big-endian floats at data + at, scaled, with their flag; false when not finite.
  static bool read_vector(const std::uint8_t* data, std::size_t at, double scale, std::uint32_t flag, Vec3& out,
                          std::uint32_t& flags) {
    if (at == kNone) return true;
    out = scale * Vec3(bytes::be_f32(data + at), bytes::be_f32(data + at + 4), bytes::be_f32(data + at + 8));
    flags |= flag;
    return out.allFinite();
  }

  std::uint64_t unwrap(std::uint32_t raw) {
    if (have_timestamp_ && last_raw_ >= 0xC0000000u && raw < 0x40000000u) epoch_ += std::uint64_t{1} << 32;
    have_timestamp_ = true;
    last_raw_ = raw;
    return epoch_ + raw;
  }


  const Layout l_;
  const std::size_t data_length_;
  const std::size_t packet_size_;
  const SlotLayout slots_;
  std::array<std::uint8_t, 2 * kMaxPacket> work_{};  // [0, pending_): bytes kept from the last feed
  std::size_t pending_ = 0;
  bool have_timestamp_ = false;
  std::uint32_t last_raw_ = 0;
  std::uint64_t epoch_ = 0;
};

}  // namespace

namespace {
constexpr OptionSpec kOptions[] = {
    {"yost_header", OptionType::IntegerOrString, "0x4F",
     "the wired response header bitfield set with command 221; needs success 0x01, checksum 0x08, data length 0x40"},
    {"yost_data_length", OptionType::IntegerOrString, "16",
     "data bytes per streamed packet (16..255; default: what yost_slots takes); bytes after the slots read are skipped"},
    {"yost_slots", OptionType::String, "0x00",
     "the streaming slot commands (command 80) in order, slot 0 = 0x00; 0x25 (corrected gyro, accel, compass), "
     "0x26 (gyro), 0x27 (accel), 0x28 (compass) after it are read as raw readings"},
};
}  // namespace

const DecoderEntry kYostDecoder{"yost", "Yost Labs 3-Space: streamed tared quaternion (and corrected gyro, accel, compass) with the wired response header",
                                kOptions, make_yost_decoder};

std::unique_ptr<Decoder> make_yost_decoder(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  const std::string header = read.text("yost_header");
  const std::string data_length = read.text("yost_data_length");
  std::uint32_t bits = 0;
  if (!parse_unsigned(header, bits) || (bits & ~kAllBits) != 0 || (bits & kRequiredBits) != kRequiredBits)
    throw OptionError("yost_header",
                      "expected the command-221 bitfield (e.g. \"0x4F\") with success 0x01, checksum 0x08 and "
                      "data length 0x40 and no bit above 0x40, got \"" + header + "\"");
  const SlotLayout slots = parse_slots(read.text("yost_slots"));
  std::uint32_t length = 0;
  if (!read.has("yost_data_length")) {
    length = static_cast<std::uint32_t>(slots.bytes);
  } else if (!parse_unsigned(data_length, length) || length < kQuaternionBytes || length > 255) {
    throw OptionError("yost_data_length", "expected 16..255 (bytes per streamed packet), got \"" + data_length + "\"");
  }
  if (length < slots.bytes)
    throw OptionError("yost_data_length", "the slots of yost_slots take " + std::to_string(slots.bytes) +
                                              " bytes, more than " + data_length);
  return std::make_unique<YostDecoder>(bits, length, slots);
}

std::vector<std::uint8_t> encode_yost_vectors(std::initializer_list<Vec3> vectors) {
  std::vector<std::uint8_t> out(12 * vectors.size());
  std::uint8_t* p = out.data();
  for (const Vec3& v : vectors)
    for (int i = 0; i < 3; ++i, p += 4) bytes::put_be_f32(p, static_cast<float>(v[i]));
  return out;
}

std::vector<std::uint8_t> encode_yost_quaternion_packet(const Quat& q, std::uint32_t timestamp_us,
                                                        const YostPacketFields& fields) {
  std::vector<std::uint8_t> data(kQuaternionBytes + fields.extra.size());
  bytes::put_be_f32(data.data(), static_cast<float>(q.x()));
  bytes::put_be_f32(data.data() + 4, static_cast<float>(q.y()));
  bytes::put_be_f32(data.data() + 8, static_cast<float>(q.z()));
  bytes::put_be_f32(data.data() + 12, static_cast<float>(q.w()));
  if (!fields.extra.empty()) std::memcpy(data.data() + kQuaternionBytes, fields.extra.data(), fields.extra.size());

  // Written at fixed offsets into a buffer of the final size (GCC 12 warns spuriously about
  // vector::insert after push_back).
  const std::uint32_t h = fields.header;
  const Layout l = layout_of(h);
  std::vector<std::uint8_t> out(l.header_size + data.size());
  std::uint8_t* p = out.data();
  if (h & kYostSuccess) p[l.success] = fields.failure;
  if (h & kYostTimestamp) bytes::put_be_u32(p + l.timestamp, timestamp_us);
  if (h & kYostCommandEcho) p[l.echo] = fields.command_echo;
  if (h & kYostChecksum) p[l.checksum] = static_cast<std::uint8_t>(checksum::sum8(data) + fields.checksum_delta);
  if (h & kYostLogicalId) p[l.logical_id] = fields.logical_id;
  if (h & kYostSerialNumber) bytes::put_be_u32(p + l.serial_number, fields.serial_number);
  if (h & kYostDataLength) p[l.length] = static_cast<std::uint8_t>(data.size());
  std::memcpy(p + l.header_size, data.data(), data.size());
  return out;
}

}  // namespace posefair::drivers
