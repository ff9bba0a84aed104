// WitMotion serial protocol decoder ("witmotion").
//
// Reference documents (WitMotion Shenzhen Co., Ltd., http://wiki.wit-motion.com/english):
//   - "WT901 Datasheet" v20-0702, ch. 5 Communication Protocol: 5.1.4 Angle Output (0x53, its
//     axis and Euler-order note), 5.2.8 Return Content (the RSW bits that enable each packet).
//   - "WT901SDCL Datasheet" v20-0605, ch. 6: 6.1.1 Time Output (0x50), 6.1.6 Quaternion (0x59).
//   - docs.wit-motion.com, HWT905-TTL "Protocol" page (the same packet layouts).
// Every packet is 11 bytes: 0x55, a type byte, four little-endian 16-bit words, and SUM = the
// low byte of the sum of the first 10 bytes.
//
// What is decoded:
//   0x59 quaternion: Q0..Q3 = int16 / 32768. The documents list Q0 first and, in the usual Q0
//     notation, Q0 is the scalar, so the default is witmotion_scalar = "first" (w x y z);
//     "last" (x y z w) is there for firmware or bridges that reorder. A device at rest in its
//     reference attitude sends Q0 ≈ 1 with "first". int16 cannot hold +1.0 (32767/32768), so
//     the quaternion is renormalised; one whose norm is outside [0.9, 1.1] (all zeros, or a
//     corrupted frame whose checksum still matched) counts as malformed.
//   0x53 angles: roll (X), pitch (Y), yaw (Z) = int16 · 180/32768 degrees, then a version word
//     (temperature on older models), unused. The documents: "Euler angle represents the rotation
//     order of the coordinate system when the attitude is defined as Z-Y-X, that is, first turn
//     around the Z-axis, then turn around the Y-axis, and then turn around the X-axis". Read as
//     intrinsic z-y'-x'' (aerospace) angles with right-handed positive rotations, the rotation
//     from sensor to world is R = Rz(yaw) · Ry(pitch) · Rx(roll); euler_to_quat({Z, Y, X}) is
//     exactly that composition, so it is reused. The documents give pitch a range of ±90°; a
//     frame with |pitch| > 90° counts as malformed.
//   0x50 time: YY MM DD hh mm ss, then milliseconds (16 bit). The document's checksum line for
//     this packet reads "0x55+0x51+...+TL" (copied from 0x51); the device sums the first 10 bytes
//     like every other packet, and so does this decoder.
//   0x51 acceleration: ax ay az = int16 / 32768 · 16 g, "g is Gravity acceleration, 9.8m/s2"
//     (HWT905-TTL "Protocol", Acceleration Output): m/s² = int16 · 16 · 9.8 / 32768; then a
//     temperature word, unused.
//   0x52 angular velocity: wx wy wz = int16 / 32768 · 2000 °/s (same page, Angular Velocity
//     Output): rad/s = int16 · 2000 / 32768 · π/180; then a temperature word, unused.
//   0x54 magnetic field: Hx Hy Hz = int16 (WT901 Datasheet 5.1.5 gives no unit; the WT901BLECL
//     Datasheet v20-0707, 6.1.2.1, reading the same registers, says "Unit: mG"): µT = int16 ·
//     0.1. Its example (x = 360, y = 105, z = 122 mG, |H| = 39 µT) is an earth field's size.
//   0x55 port, 0x56 pressure, 0x57/0x58/0x5A GPS, and the undocumented 0x5B..0x5F: valid
//     frames, counted as ignored_frames. A type byte outside
//     0x50..0x5F is not a frame start (the 0x55 is skipped as garbage), which makes a false
//     start in garbage 16 times rarer than accepting any type.
//
// Choices:
//   - Raw readings (0x51, 0x52, 0x54) ride with the orientation of their output cycle. The
//     device sends a cycle's packets in ascending type order, so the acceleration and angular
//     velocity (and the magnetic field, before a 0x59) arrive before the cycle's orientation
//     frame: they are held and the orientation sample carries them (kHasAccel, kHasGyro,
//     kHasMag). Readings that no orientation follows in their cycle (the device streams raw
//     data only, the orientation frame was lost, or 0x54 comes after an angles-only 0x53) are
//     sent alone as a raw-only sample (kNoOrientation) when the cycle ends: at the next cycle's
//     first packet, or, once two cycles in a row ended so at the same packet type, at that type
//     (without waiting; one lost orientation frame does not teach a wrong end). A reading of a
//     type already held replaces it.
//   - Quaternion preferred: a device may send both 0x53 and 0x59 each cycle; once a 0x59 has
//     been seen, 0x53 frames are ignored_frames. Two 0x53 frames with no 0x59 between them mean
//     the quaternion output was switched off, and 0x53 frames produce samples again (so the
//     first cycle of a device sending both gives two samples, and a switch-off loses one).
//   - Device time: a valid 0x50 frame stamps (kHasDeviceTime) the samples that follow it in the
//     same output cycle. The cycle ends at the next 0x50, or when a packet type repeats without a
//     0x50 in between (the time frame of that cycle was lost): samples then carry no device time
//     rather than a stale one. device_time = the time of day (hh:mm:ss.ms) plus 86400 s per day
//     rollover, detected as the time of day falling back by more than 12 hours; smaller steps
//     back (a clock being set) pass through. The date bytes are not used (the RTC of a module
//     without GPS is often never set). Impossible times (hour > 23, minute > 59, second > 60,
//     ms > 999) are malformed and clear the time.
//   - The decoder never remaps axes: the WT901 datasheet draws X right / Y forward / Z up, the
//     WT901BLECL one X forward / Y left / Z up; samples are in the module's own axes, world
//     frame east-north-up ("northeast sky") with yaw relative to the module's reference.
//   - Every valid frame lands in exactly one of: a sample (its orientation or one of its raw
//     readings), ignored_frames, malformed. Bytes not
//     part of a valid frame are skipped_bytes; each run of them is one resync. A frame whose
//     checksum fails counts in bad_checksum, and the search resumes at its second byte (so a
//     good frame starting inside it is still found).
#include "posefair/drivers/witmotion_decoder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>

#include "posefair/core/euler_angles.hpp"
#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/checksums.hpp"
#include "frame_feed.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint8_t kHeader = 0x55;
constexpr std::size_t kFrameSize = kWitMotionFrameSize;
constexpr std::uint8_t kTypeTime = 0x50;
constexpr std::uint8_t kTypeAccel = 0x51;
constexpr std::uint8_t kTypeGyro = 0x52;
constexpr std::uint8_t kTypeAngles = 0x53;
constexpr std::uint8_t kTypeMag = 0x54;
constexpr std::uint8_t kTypeQuaternion = 0x59;
constexpr double kQuatScale = 1.0 / 32768.0;
constexpr double kAngleScale = 180.0 / 32768.0;
constexpr double kAccelScale = 16.0 * 9.8 / 32768.0;                          // m/s² per count
constexpr double kGyroScale = 2000.0 / 32768.0 * std::numbers::pi / 180.0;  // rad/s per count
constexpr double kMagScale = 0.1;                                             // µT per count (mG)
constexpr std::int64_t kDayMs = 86'400'000;

bool is_frame_type(std::uint8_t type) { return (type & 0xF0u) == 0x50u; }

std::int16_t saturate_i16(double v) {
  const double r = std::round(v);
  if (!(r >= -32768.0)) return -32768;  // also NaN
  if (r > 32767.0) return 32767;
  return static_cast<std::int16_t>(r);
}

std::uint16_t wrap_i16(double v) {
  if (!std::isfinite(v)) return 0;
  const double r = std::round(std::fmod(v, 65536.0));
  return static_cast<std::uint16_t>(static_cast<std::int32_t>(r) & 0xFFFF);
}

class WitMotionDecoder final : public Decoder {
 public:
  explicit WitMotionDecoder(bool scalar_first) : scalar_first_(scalar_first) {}

  std::string_view protocol() const override { return "witmotion"; }

  void feed(std::span<const std::uint8_t> in, DecodedSink& sink) override {
    counters_.bytes += in.size();
    carry_.feed(in, [&](const std::uint8_t* p, std::size_t n, std::size_t limit) { return scan(p, n, limit, sink); });
  }

  void reset() override {
    carry_.reset();
    end_resync();
    quaternion_seen_ = false;
    angles_since_quaternion_ = 0;
    time_valid_ = false;
    have_time_of_day_ = false;
    last_time_of_day_ms_ = 0;
    day_offset_ms_ = 0;
    cycle_types_ = 0;
    raw_ = {};
    last_type_ = 0;
    leftover_end_type_ = 0;
    cycle_end_type_ = 0;
    flushed_early_ = false;
  }

 private:
  // Decides the stream positions p[0], p[1], ... while they are < limit; returns the position
  // it stopped at: >= limit, or < limit where a frame starts that needs bytes beyond p[n-1].
  std::size_t scan(const std::uint8_t* p, std::size_t n, std::size_t limit, DecodedSink& sink) {
    std::size_t pos = 0;
    while (pos < limit) {
      if (p[pos] != kHeader) {
        const void* hit = std::memchr(p + pos, kHeader, limit - pos);
        const std::size_t next = hit ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(hit) - p) : limit;
        skip(next - pos);
        pos = next;
        continue;
      }
      if (n - pos < kFrameSize) break;
      const std::uint8_t* f = p + pos;
      if (!is_frame_type(f[1])) {
        skip(1);
        ++pos;
        continue;
      }
      if (checksum::sum8({f, kFrameSize - 1}) != f[kFrameSize - 1]) {
        ++counters_.bad_checksum;
        skip(1);
        ++pos;
        continue;
      }
      end_resync();
      accept(f, sink);
      pos += kFrameSize;
    }
    return pos;
  }


  void accept(const std::uint8_t* f, DecodedSink& sink) {
    ++counters_.frames;
    const std::uint8_t type = f[1];
    const std::uint8_t* d = f + 2;
    const auto bit = static_cast<std::uint16_t>(1u << (type & 0x0Fu));
    if (type == kTypeTime) {
      end_cycle(sink);
      last_type_ = type;
      cycle_types_ = bit;
      on_time(d);
      return;
    }
    if ((cycle_types_ & bit) != 0) {  // a new cycle began without its time frame
      end_cycle(sink);
      time_valid_ = false;
      cycle_types_ = 0;
    }
    cycle_types_ = static_cast<std::uint16_t>(cycle_types_ | bit);
    last_type_ = type;
    switch (type) {
      case kTypeQuaternion: on_quaternion(d, sink); break;
      case kTypeAngles: on_angles(d, sink); break;
      case kTypeAccel: on_raw(kHasAccel, raw_.accel, d, kAccelScale, type, sink); break;
      case kTypeGyro: on_raw(kHasGyro, raw_.gyro, d, kGyroScale, type, sink); break;
      case kTypeMag: on_raw(kHasMag, raw_.mag, d, kMagScale, type, sink); break;
      default: ++counters_.ignored_frames; break;
    }
  }

  // The cycle is over: readings no orientation took go out alone. Two cycles in a row that
  // ended so, at the same packet type, make that type the end of the next cycle's raw part.
  void end_cycle(DecodedSink& sink) {
    const bool leftover = raw_.flags != 0 || flushed_early_;
    if (raw_.flags != 0) emit_raw_only(sink);
    cycle_end_type_ = leftover && last_type_ == leftover_end_type_ ? last_type_ : 0;
    leftover_end_type_ = leftover ? last_type_ : 0;
    flushed_early_ = false;
  }

  void on_raw(std::uint32_t flag, Vec3& into, const std::uint8_t* d, double scale, std::uint8_t type,
              DecodedSink& sink) {
    into = Vec3(bytes::le_i16(d), bytes::le_i16(d + 2), bytes::le_i16(d + 4)) * scale;
    raw_.flags |= flag;
    if (type == cycle_end_type_) {  // the last packet of a cycle: no orientation follows
      emit_raw_only(sink);
      flushed_early_ = true;
    }
  }

  void emit_raw_only(DecodedSink& sink) {
    DecodedSample s;
    s.flags = kNoOrientation;
    emit(s, sink);
  }

  void on_time(const std::uint8_t* d) {
    const int hour = d[3], minute = d[4], second = d[5];
    const int ms = bytes::le_u16(d + 6);
    if (hour > 23 || minute > 59 || second > 60 || ms > 999) {
      ++counters_.malformed;
      time_valid_ = false;
      return;
    }
    ++counters_.ignored_frames;  // a valid frame without an orientation
    const std::int64_t tod = ((static_cast<std::int64_t>(hour) * 60 + minute) * 60 + second) * 1000 + ms;
    if (have_time_of_day_ && tod < last_time_of_day_ms_ - kDayMs / 2) day_offset_ms_ += kDayMs;
    have_time_of_day_ = true;
    last_time_of_day_ms_ = tod;
    time_ = static_cast<double>(day_offset_ms_ + tod) / 1000.0;
    time_valid_ = true;
  }

  void on_quaternion(const std::uint8_t* d, DecodedSink& sink) {
    const double c0 = bytes::le_i16(d) * kQuatScale;
    const double c1 = bytes::le_i16(d + 2) * kQuatScale;
    const double c2 = bytes::le_i16(d + 4) * kQuatScale;
    const double c3 = bytes::le_i16(d + 6) * kQuatScale;
    Quat q = scalar_first_ ? Quat(c0, c1, c2, c3) : Quat(c3, c0, c1, c2);
    const double norm = q.norm();
    if (!(norm >= 0.9 && norm <= 1.1)) {
      ++counters_.malformed;
      return;
    }
    quaternion_seen_ = true;
    angles_since_quaternion_ = 0;
    q.coeffs() /= norm;
    DecodedSample s;
    s.orientation = q;
    emit(s, sink);
  }

  void on_angles(const std::uint8_t* d, DecodedSink& sink) {
    if (quaternion_seen_ && ++angles_since_quaternion_ < 2) {
      ++counters_.ignored_frames;  // the 0x59 of this cycle carries the orientation
      return;
    }
    quaternion_seen_ = false;
    angles_since_quaternion_ = 0;
    const std::int16_t pitch_raw = bytes::le_i16(d + 2);
    if (pitch_raw > 16384 || pitch_raw < -16384) {
      ++counters_.malformed;
      return;
    }
    static constexpr std::array<Axis, 3> kZYX = {Axis::Z, Axis::Y, Axis::X};
    const std::array<double, 3> deg = {bytes::le_i16(d + 4) * kAngleScale, pitch_raw * kAngleScale,
                                       bytes::le_i16(d) * kAngleScale};
    DecodedSample s;
    s.orientation = euler_to_quat(kZYX, deg);
    emit(s, sink);
  }

  // Sends s with the held raw readings and the cycle's device time.
  void emit(DecodedSample& s, DecodedSink& sink) {
    s.flags |= raw_.flags;
    s.gyro = raw_.gyro;
    s.accel = raw_.accel;
    s.mag = raw_.mag;
    raw_ = {};
    if (time_valid_) {
      s.flags |= kHasDeviceTime;
      s.device_time = time_;
    }
    ++counters_.samples;
    sink.on_sample(s);
  }

  const bool scalar_first_;
  detail::SplitFrameCarry<kFrameSize> carry_;
  bool quaternion_seen_ = false;
  int angles_since_quaternion_ = 0;
  bool time_valid_ = false;
  double time_ = 0.0;
  bool have_time_of_day_ = false;
  std::int64_t last_time_of_day_ms_ = 0;
  std::int64_t day_offset_ms_ = 0;
  std::uint16_t cycle_types_ = 0;  // bit (type & 15) for each packet type seen since the last 0x50
  struct Raw {
    std::uint32_t flags = 0;  // kHasAccel, kHasGyro, kHasMag held for the cycle's sample
    Vec3 gyro = Vec3::Zero(), accel = Vec3::Zero(), mag = Vec3::Zero();
  } raw_;
  std::uint8_t last_type_ = 0;           // the type of the current cycle's latest frame
  std::uint8_t leftover_end_type_ = 0;   // the last type of the previous cycle if readings were left over, else 0
  std::uint8_t cycle_end_type_ = 0;      // send readings alone at this type (0: wait for the cycle's end)
  bool flushed_early_ = false;           // this cycle's readings went out at cycle_end_type_
};

}  // namespace

namespace {
constexpr std::string_view kScalarChoices[] = {"first", "last"};
constexpr OptionSpec kOptions[] = {
    {"witmotion_scalar", OptionType::String, "first",
     "which int16 of the 0x59 quaternion frame is the scalar: first (w x y z) or last (x y z w)", kScalarChoices},
};
}  // namespace

const DecoderEntry kWitMotionDecoder{"witmotion", "WitMotion WT901 family: 0x55 frames, quaternion (0x59) or angles (0x53), with acceleration, angular velocity and magnetic field (0x51, 0x52, 0x54)",
                                     kOptions, make_witmotion_decoder};

std::unique_ptr<Decoder> make_witmotion_decoder(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  const std::string scalar = read.text("witmotion_scalar");
  if (scalar == "first") return std::make_unique<WitMotionDecoder>(true);
  if (scalar == "last") return std::make_unique<WitMotionDecoder>(false);
  throw OptionError("witmotion_scalar", "must be \"first\" or \"last\", not \"" + scalar + "\"");
}

std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_frame(std::uint8_t type,
                                                                     const std::array<std::uint8_t, 8>& data) {
  std::array<std::uint8_t, kWitMotionFrameSize> f{};
  f[0] = kHeader;
  f[1] = type;
  std::copy(data.begin(), data.end(), f.begin() + 2);
  f[10] = checksum::sum8({f.data(), 10});
  return f;
}

std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_quaternion(const Quat& q, bool scalar_first) {
  const std::array<double, 4> c = scalar_first ? std::array<double, 4>{q.w(), q.x(), q.y(), q.z()}
                                               : std::array<double, 4>{q.x(), q.y(), q.z(), q.w()};
  std::array<std::uint8_t, 8> data{};
  for (std::size_t i = 0; i < 4; ++i)
    bytes::put_le_u16(data.data() + 2 * i, static_cast<std::uint16_t>(saturate_i16(c[i] * 32768.0)));
  return encode_witmotion_frame(kTypeQuaternion, data);
}

std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_angles(double roll_deg, double pitch_deg, double yaw_deg,
                                                                      std::uint16_t version) {
  std::array<std::uint8_t, 8> data{};
  bytes::put_le_u16(data.data(), wrap_i16(roll_deg / kAngleScale));
  bytes::put_le_u16(data.data() + 2, wrap_i16(pitch_deg / kAngleScale));
  bytes::put_le_u16(data.data() + 4, wrap_i16(yaw_deg / kAngleScale));
  bytes::put_le_u16(data.data() + 6, version);
  return encode_witmotion_frame(kTypeAngles, data);
}

std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_vector(std::uint8_t type, const Vec3& v,
                                                                      std::uint16_t temperature) {
  const double scale = type == kTypeAccel ? kAccelScale : type == kTypeGyro ? kGyroScale : kMagScale;
  std::array<std::uint8_t, 8> data{};
  for (int i = 0; i < 3; ++i)
    bytes::put_le_u16(data.data() + 2 * i, static_cast<std::uint16_t>(saturate_i16(v[i] / scale)));
  bytes::put_le_u16(data.data() + 6, temperature);
  return encode_witmotion_frame(type, data);
}

std::array<std::uint8_t, kWitMotionFrameSize> encode_witmotion_time(int yy, int month, int day, int hour, int minute,
                                                                    int second, int millisecond) {
  std::array<std::uint8_t, 8> data{};
  data[0] = static_cast<std::uint8_t>(yy);
  data[1] = static_cast<std::uint8_t>(month);
  data[2] = static_cast<std::uint8_t>(day);
  data[3] = static_cast<std::uint8_t>(hour);
  data[4] = static_cast<std::uint8_t>(minute);
  data[5] = static_cast<std::uint8_t>(second);
  bytes::put_le_u16(data.data() + 6, static_cast<std::uint16_t>(millisecond));
  return encode_witmotion_frame(kTypeTime, data);
}

}  // namespace posefair::drivers
