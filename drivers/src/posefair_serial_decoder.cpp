// posefair's serial protocol for microcontroller trackers: registry name "posefair".
//
// Reference document: docs/protocol.md, section "Serial protocol for microcontroller trackers"
// (posefair, protocol version 1; this file and that section are one specification: where
// they disagree, this file is wrong). Two forms share one line and may be interleaved:
// - the text sentence "$PFQ,<time µs>,<w>,<x>,<y>,<z>[,<px>,<py>,<pz>]*HH\r\n", HH the XOR of
//   the bytes between '$' and '*' (upper or lower case hex);
// - the raw-IMU sentence "$PFI,<time µs>,<gx>,<gy>,<gz>,<ax>,<ay>,<az>[,<mx>,<my>,<mz>]*HH\r\n"
//   (gyroscope rad/s, accelerometer m/s², magnetometer µT, sensor axes): a raw-only sample;
// - the binary frame F5 50 | version 1 | flags | length | u32 LE time µs | [4 × float32 LE
//   w x y z, unless flag bit 3] | [3 × float32 LE position, metres, flag bit 0] | [6 × float32
//   LE gyroscope then accelerometer, flag bit 1] | [3 × float32 LE magnetometer, flag bit 2] |
//   CRC-16/CCITT-FALSE LE over version .. payload end. Bit 3 (no orientation: a raw-only
//   sample) needs bit 1 or 2 and excludes bit 0.
// The device time is a u32 count of microseconds that wraps at 2^32 µs (71.6 min), Arduino's
// micros(); device_time is it in seconds, unwrapped forward-only (each step modulo 2^32, so a
// device restart looks like a rollover; reset() starts afresh). The text and binary forms
// share one clock. Every valid frame whose time field reads advances the unwrapping, also one
// that then turns out malformed (say, by its quaternion).
//
// Choices (the document states them for senders and receivers)
// - The sync bytes F5 50: 0xF5 never occurs in ASCII or UTF-8 text, so neither the sentences
//   nor an Arduino's debug prints on the same line can start a false binary frame, and F5 50
//   collides with none of the other protocols' starts (WitMotion 55, BNO08x RVC AA AA, Xsens
//   FA FF, VectorNav FA, u-blox B5 62, NMEA '$', MAVLink FE/FD, RTCM D3).
// - Sentences: at most 255 bytes from '$' through '\n'. A candidate sentence is abandoned
//   (its bytes skipped) at a byte that cannot occur in one (outside 0x20..0x7E, other than
//   '\r' and '\n') or at a new '$' (the line was cut; the new '$' starts the next sentence).
//   255 bytes without '\n' count as malformed and are dropped whole (none of them can start a
//   frame). A line from '$' to '\n' without a well-formed "*HH" ending, or with a checksum that
//   does not match, counts as bad_checksum and is dropped whole. Valid sentences of other
//   types ($GPGGA ...) count as ignored_frames.
// - Raw readings must be finite (malformed otherwise); their size is not judged here (a
//   saturated sensor is the fusion stage's to judge).
// - Binary frames: a length above 68 counts as malformed at once (no waiting for bytes a
//   corrupt length announces); after a CRC mismatch only the first sync byte is dropped and the
//   search goes on inside the rejected bytes. A version other than 1 (with a valid CRC) counts
//   as ignored_frames: later versions may change the payload. Reserved flag bits (4-7) set, an
//   impossible combination, or a length other than the flags give, count as malformed. (A
//   receiver older than the raw-IMU flags counts such frames malformed, never misreads them.)
// - Numbers in sentences are read with std::from_chars (no spaces, no '+', no hex); the time
//   is an unsigned decimal integer up to 4294967295. NaN, infinities, out-of-range numbers, a
//   quaternion whose norm differs from 1 by more than 1e-3 (the UDP protocol's bound) or a
//   wrong field count make a valid frame malformed. Quaternions are normalised (one that is
//   unit to rounding is kept exactly, so a sentence round-trips bit for bit).
// - Every byte fed is either part of a frame whose checksum matched, or counted in
//   skipped_bytes, or held as the start of an incomplete frame. A run of skipped bytes between
//   two valid frames is one resync (lines of debug text between sentences are resyncs).
#include "posefair/drivers/posefair_serial_decoder.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <optional>
#include <string_view>

#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/checksums.hpp"
#include "frame_feed.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint8_t kSync0 = 0xF5;
constexpr std::uint8_t kSync1 = 0x50;
constexpr std::uint8_t kVersion = 1;
constexpr std::uint8_t kFlagPosition = 0x01;
constexpr std::uint8_t kFlagImu = 0x02;            // gyroscope and accelerometer follow
constexpr std::uint8_t kFlagMag = 0x04;            // magnetometer follows
constexpr std::uint8_t kFlagNoOrientation = 0x08;  // no quaternion: a raw-only sample
constexpr std::uint8_t kKnownFlags = kFlagPosition | kFlagImu | kFlagMag | kFlagNoOrientation;
constexpr std::size_t kFrameHeader = 5;       // sync, sync, version, flags, length
constexpr std::size_t kMaxPayload = 68;       // time, quaternion, position, gyro + accel, mag
constexpr std::size_t kMaxSentence = 255;     // '$' through '\n'
constexpr std::size_t kBufferSize = 1024;
static_assert(kBufferSize > kMaxSentence && kBufferSize > kFrameHeader + kMaxPayload + 2);
constexpr double kUnitTolerance = 1e-3;
constexpr double kMicro = 1e-6;

bool sentence_byte(std::uint8_t b) { return (b >= 0x20 && b <= 0x7E) || b == '\r'; }

int hex_value(std::uint8_t c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// q normalised, or nothing if it is not finite or not unit within the tolerance.
std::optional<Quat> unit(double w, double x, double y, double z) {
  Quat q(w, x, y, z);
  const double n2 = q.squaredNorm();
  if (!std::isfinite(n2)) return std::nullopt;
  const double n = std::sqrt(n2);
  if (!(std::abs(n - 1.0) <= kUnitTolerance)) return std::nullopt;
  if (std::abs(n2 - 1.0) > 4e-15) q.coeffs() /= n;
  return q;
}

class PosefairSerialDecoder final : public Decoder {
 public:
  std::string_view protocol() const override { return "posefair"; }

  void feed(std::span<const std::uint8_t> in, DecodedSink& sink) override {
    counters_.bytes += in.size();
    buffer_.feed(in, [&](const std::uint8_t* data, std::size_t held) { return process(data, held, sink); });
  }

  void reset() override {
    buffer_.reset();
    end_resync();
    have_time_ = false;
  }

 private:
  void accept_frame() {
    ++counters_.frames;
    end_resync();
  }

  double unwrap_time(std::uint32_t raw) {
    time_us_ = have_time_ ? time_us_ + static_cast<std::uint32_t>(raw - last_time_) : raw;
    have_time_ = true;
    last_time_ = raw;
    return static_cast<double>(time_us_) * kMicro;
  }

  std::size_t process(const std::uint8_t* data, std::size_t held, DecodedSink& sink) {
    std::size_t i = 0;
    while (i < held) {
      const std::uint8_t* p = data + i;
      const std::size_t avail = held - i;
      if (p[0] == '$') {
        const std::size_t limit = std::min(avail, kMaxSentence);
        std::size_t j = 1;
        while (j < limit && p[j] != '\n' && p[j] != '$' && sentence_byte(p[j])) ++j;
        if (j < limit && p[j] == '\n') {
          handle_sentence(p, j + 1, sink);
          i += j + 1;
          continue;
        }
        if (j < limit) {  // cut off by a new '$' or by a byte no sentence holds
          skip(j);
          i += j;
          continue;
        }
        if (limit < kMaxSentence) break;  // wait for the rest of the line
        ++counters_.malformed;            // no '\n' within the bound
        skip(kMaxSentence);
        i += kMaxSentence;
        continue;
      }
      if (p[0] == kSync0) {
        if (avail < 2) break;
        if (p[1] != kSync1) {
          skip(1);
          ++i;
          continue;
        }
        if (avail < kFrameHeader) break;
        const std::size_t len = p[4];
        if (len > kMaxPayload) {
          ++counters_.malformed;
          skip(1);
          ++i;
          continue;
        }
        const std::size_t total = kFrameHeader + len + 2;
        if (avail < total) break;
        const std::uint16_t crc = checksum::crc16_ccitt({p + 2, 3 + len}, 0xFFFF);
        if (crc != bytes::le_u16(p + kFrameHeader + len)) {
          ++counters_.bad_checksum;
          skip(1);
          ++i;
          continue;
        }
        accept_frame();
        handle_frame(p[2], p[3], {p + kFrameHeader, len}, sink);
        i += total;
        continue;
      }
      std::size_t k = 1;
      while (k < avail && p[k] != '$' && p[k] != kSync0) ++k;
      skip(k);
      i += k;
    }
    return i;
  }

  // line: '$' through '\n' (n bytes), every byte in between a sentence byte.
  void handle_sentence(const std::uint8_t* line, std::size_t n, DecodedSink& sink) {
    std::size_t end = n - 1;  // the '\n'
    if (end > 0 && line[end - 1] == '\r') --end;
    int h1 = -1, h0 = -1;
    if (end >= 4 && line[end - 3] == '*') {
      h1 = hex_value(line[end - 2]);
      h0 = hex_value(line[end - 1]);
    }
    const std::span<const std::uint8_t> body(line + 1, end >= 4 ? end - 4 : 0);
    if (h1 < 0 || h0 < 0 || std::find(body.begin(), body.end(), '\r') != body.end() ||
        checksum::xor8(body) != (h1 << 4 | h0)) {
      ++counters_.bad_checksum;
      skip(n);
      return;
    }
    accept_frame();

    const char* s = reinterpret_cast<const char*>(body.data());
    const char* const e = s + body.size();
    const char* comma = std::find(s, e, ',');
    const std::string_view type(s, static_cast<std::size_t>(comma - s));
    const bool imu = type == "PFI";
    if (type != "PFQ" && !imu) {
      ++counters_.ignored_frames;
      return;
    }
    std::array<std::string_view, 11> fields;
    std::size_t count = 0;
    while (comma != e) {
      const char* begin = comma + 1;
      comma = std::find(begin, e, ',');
      if (count == fields.size()) {
        ++counters_.malformed;
        return;
      }
      fields[count++] = std::string_view(begin, static_cast<std::size_t>(comma - begin));
    }
    if (imu ? (count != 7 && count != 10) : (count != 5 && count != 8)) {
      ++counters_.malformed;
      return;
    }
    double device_time = 0.0;
    {
      const std::string_view f = fields[0];
      std::uint64_t t = 0;
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), t);
      if (f.empty() || ec != std::errc() || ptr != f.data() + f.size() || t > 0xFFFFFFFFu) {
        ++counters_.malformed;
        return;
      }
      device_time = unwrap_time(static_cast<std::uint32_t>(t));
    }
    std::array<double, 10> v{};
    for (std::size_t k = 1; k < count; ++k) {
      const std::string_view f = fields[k];
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v[k - 1]);
      if (f.empty() || ec != std::errc() || ptr != f.data() + f.size() || !std::isfinite(v[k - 1])) {
        ++counters_.malformed;
        return;
      }
    }
    DecodedSample sample;
    sample.flags = kHasDeviceTime;
    sample.device_time = device_time;
    if (imu) {
      sample.flags |= kNoOrientation | kHasGyro | kHasAccel;
      sample.gyro = Vec3(v[0], v[1], v[2]);
      sample.accel = Vec3(v[3], v[4], v[5]);
      if (count == 10) {
        sample.mag = Vec3(v[6], v[7], v[8]);
        sample.flags |= kHasMag;
      }
      ++counters_.samples;
      sink.on_sample(sample);
      return;
    }
    const std::optional<Quat> q = unit(v[0], v[1], v[2], v[3]);
    if (!q) {
      ++counters_.malformed;
      return;
    }
    sample.orientation = *q;
    if (count == 8) {
      sample.position = Vec3(v[4], v[5], v[6]);
      sample.flags |= kHasPosition;
    }
    ++counters_.samples;
    sink.on_sample(sample);
  }

  void handle_frame(std::uint8_t version, std::uint8_t flags, std::span<const std::uint8_t> payload,
                    DecodedSink& sink) {
    if (version != kVersion) {
      ++counters_.ignored_frames;
      return;
    }
    const bool no_orientation = (flags & kFlagNoOrientation) != 0;
    if ((flags & ~kKnownFlags) != 0 || payload.size() != frame_payload_size(flags) ||
        (no_orientation && ((flags & (kFlagImu | kFlagMag)) == 0 || (flags & kFlagPosition) != 0))) {
      ++counters_.malformed;
      return;
    }
    const std::uint8_t* d = payload.data();
    const double device_time = unwrap_time(bytes::le_u32(d));
    std::size_t at = 4;
    const auto vec3 = [&] {
      const Vec3 v(bytes::le_f32(d + at), bytes::le_f32(d + at + 4), bytes::le_f32(d + at + 8));
      at += 12;
      return v;
    };
    DecodedSample sample;
    sample.flags = kHasDeviceTime;
    sample.device_time = device_time;
    if (no_orientation) {
      sample.flags |= kNoOrientation;
    } else {
      const std::optional<Quat> q =
          unit(bytes::le_f32(d + 4), bytes::le_f32(d + 8), bytes::le_f32(d + 12), bytes::le_f32(d + 16));
      if (!q) {
        ++counters_.malformed;
        return;
      }
      sample.orientation = *q;
      at += 16;
    }
    if ((flags & kFlagPosition) != 0) {
      sample.position = vec3();
      sample.flags |= kHasPosition;
    }
    if ((flags & kFlagImu) != 0) {
      sample.gyro = vec3();
      sample.accel = vec3();
      sample.flags |= kHasGyro | kHasAccel;
    }
    if ((flags & kFlagMag) != 0) {
      sample.mag = vec3();
      sample.flags |= kHasMag;
    }
    if (!sample.position.allFinite() || !sample.gyro.allFinite() || !sample.accel.allFinite() ||
        !sample.mag.allFinite()) {
      ++counters_.malformed;
      return;
    }
    ++counters_.samples;
    sink.on_sample(sample);
  }

  // The payload length the flags announce.
  static std::size_t frame_payload_size(std::uint8_t flags) {
    return 4 + ((flags & kFlagNoOrientation) ? 0 : 16) + ((flags & kFlagPosition) ? 12 : 0) +
           ((flags & kFlagImu) ? 24 : 0) + ((flags & kFlagMag) ? 12 : 0);
  }

  detail::MessageBuffer<kBufferSize> buffer_;
  bool have_time_ = false;
  std::uint32_t last_time_ = 0;
  std::uint64_t time_us_ = 0;
};

void append_number(std::string& out, double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, v);
  out.append(buffer, result.ptr);
}

}  // namespace

const DecoderEntry kPosefairSerialDecoder{"posefair", "posefair's own protocol for microcontrollers: $PFQ/$PFI text and F5 50 frames, orientation and raw IMU",
                                          {}, make_posefair_serial_decoder};

std::unique_ptr<Decoder> make_posefair_serial_decoder(const OptionMap& options) {
  (void)OptionReader({}, options);  // it reads none: refuses any
  return std::make_unique<PosefairSerialDecoder>();
}

namespace {
// "$<type>,<time>,<numbers...>*HH\r\n".
std::string sentence(std::string_view type, std::uint32_t device_time_us, std::initializer_list<const double*> runs,
                     std::initializer_list<std::size_t> lengths) {
  std::string s = "$";
  s += type;
  s += ',';
  s += std::to_string(device_time_us);
  auto length = lengths.begin();
  for (const double* run : runs) {
    const std::size_t n = *length++;
    if (run == nullptr) continue;
    for (std::size_t k = 0; k < n; ++k) {
      s += ',';
      append_number(s, run[k]);
    }
  }
  const std::uint8_t x =
      checksum::xor8({reinterpret_cast<const std::uint8_t*>(s.data()) + 1, s.size() - 1});
  constexpr char kHex[] = "0123456789ABCDEF";
  s += '*';
  s += kHex[x >> 4];
  s += kHex[x & 0xF];
  s += "\r\n";
  return s;
}
}  // namespace

std::string encode_posefair_sentence(std::uint32_t device_time_us, const Quat& q, const Vec3* position) {
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  return sentence("PFQ", device_time_us, {wxyz, position ? position->data() : nullptr}, {4, 3});
}

std::string encode_posefair_imu_sentence(std::uint32_t device_time_us, const Vec3& gyro, const Vec3& accel,
                                         const Vec3* mag) {
  return sentence("PFI", device_time_us, {gyro.data(), accel.data(), mag ? mag->data() : nullptr}, {3, 3, 3});
}

std::vector<std::uint8_t> encode_posefair_frame(std::uint32_t device_time_us, const Quat& q, const Vec3* position) {
  return encode_posefair_frame(device_time_us, &q, position, nullptr, nullptr);
}

std::vector<std::uint8_t> encode_posefair_frame(std::uint32_t device_time_us, const Quat* q, const Vec3* position,
                                                const PosefairImuReading* imu, const Vec3* mag) {
  const auto flags = static_cast<std::uint8_t>((q ? 0 : kFlagNoOrientation) | (position ? kFlagPosition : 0) |
                                               (imu ? kFlagImu : 0) | (mag ? kFlagMag : 0));
  std::vector<std::uint8_t> f = {kSync0, kSync1, kVersion, flags, 0};
  const auto put = [&](double v) {
    f.resize(f.size() + 4);
    bytes::put_le_f32(f.data() + f.size() - 4, static_cast<float>(v));
  };
  f.resize(f.size() + 4);
  bytes::put_le_u32(f.data() + kFrameHeader, device_time_us);
  if (q)
    for (double v : {q->w(), q->x(), q->y(), q->z()}) put(v);
  for (const Vec3* v : {position, imu ? &imu->gyro : nullptr, imu ? &imu->accel : nullptr, mag})
    if (v)
      for (int k = 0; k < 3; ++k) put((*v)[k]);
  const std::size_t len = f.size() - kFrameHeader;
  f[4] = static_cast<std::uint8_t>(len);
  f.resize(f.size() + 2);
  bytes::put_le_u16(f.data() + kFrameHeader + len, checksum::crc16_ccitt({f.data() + 2, 3 + len}, 0xFFFF));
  return f;
}

}  // namespace posefair::drivers
