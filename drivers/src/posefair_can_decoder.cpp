// posefair's own CAN layout for microcontroller trackers: registry name "posefair-can".
//
// Reference document: docs/can-protocol.md (posefair, CAN layout version 1; this file and that
// document are one specification: where they disagree, this file is wrong). Summary, with B the
// configured base identifier (posefair_base_id, default 0x200; posefair_id_format "standard"
// 11-bit or "extended" 29-bit), all numbers little-endian:
//   B     TIME        DLC 5: seq (u8), device time (u32, µs, wraps at 2^32: Arduino micros())
//   B + 1 POSITION    DLC 7: seq (u8), x, y, z (int16 each, millimetres, world frame)
//   B + 2 QUATERNION  DLC 8: w, x, y, z (int16 each, value / 32767; -32768 is not allowed)
//   B + 3 RAW         DLC 8: seq (u8), kind (u8: bits 0-1 0 gyroscope, 1 accelerometer,
//                     2 magnetometer; bit 7 last of the set; bits 2-6 zero), x, y, z (int16:
//                     0.001 rad/s, 0.01 m/s², 0.01 µT)
// The quaternion rotates sensor coordinates into world coordinates (v_w = q v_s q*), as on
// posefair's UDP and serial protocols.
//
// How a sample is completed (the choices the document states)
// - The quaternion frame completes a sample. It takes the TIME and POSITION frames received
//   since the previous quaternion frame (the "pending set"); they must all carry one sequence
//   number. A sample has device time and position only when their frames arrived.
// - A TIME or POSITION frame whose seq differs from the pending set's, or that repeats a kind
//   the set already has, means the sequence moved on without its quaternion: the pending set is
//   dropped (one resync, its bytes skipped) and the new frame starts the next set. Senders send
//   TIME, POSITION, QUATERNION in that order; the identifiers rise in that order too, so a
//   controller that queues all three at once still sends them in that order (the lowest
//   identifier wins arbitration).
// - A malformed quaternion frame drops the pending set as well, so that set cannot be paired
//   with the next sample's quaternion.
// - Known limit: the quaternion frame carries no seq (four int16 fill a classic frame). If a
//   quaternion frame and all the optional frames of the next sample are lost, that next
//   quaternion takes the previous sample's set. It needs three particular frames lost in a row;
//   the bus itself never loses a frame silently (CRC and retransmission), only an overloaded
//   receiver can.
// - RAW frames make raw-only samples of their own (kNoOrientation), never part of the
//   quaternion's sample: their identifier is the highest, so a controller that queues a whole
//   period at once sends them after the quaternion, which has already completed its sample. The
//   RAW frames of one seq form a raw set (a kind repeated, or another seq, drops the open set:
//   a resync); the frame with bit 7 completes it. Its device time is that of the latest TIME
//   frame of the same seq, whether a quaternion took it already or not (a raw-only tracker
//   sends TIME, then RAW frames: the RAW set takes the pending set's time and closes it).
// - The device time is unwrapped forward-only (each step modulo 2^32 µs), in every valid TIME
//   frame, also one whose set is later dropped, so device time never goes back; seq is
//   unwrapped the same way (modulo 256) into frame_counter when a sample completes with a set.
// - Checks: the DLC must be exactly 5, 7, 8 and 8 for TIME, POSITION, QUATERNION, RAW (malformed otherwise); a RAW kind above 2 or
//   with bits 2-6 set is malformed. A quaternion with a
//   component -32768 or whose norm differs from 1 by more than 1e-3 is malformed; otherwise it
//   is normalised. CAN FD frames with these identifiers are read the same way (same lengths).
// - There is no checksum in the payload: the CAN frame's own CRC-15 (CRC-17/21 for FD)
//   protects every frame on the bus, and a frame that fails it never reaches the receiver.
#include "posefair/drivers/posefair_can_decoder.hpp"

#include <array>
#include <cmath>

#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/counter_unwrap.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint32_t kTime = 0, kPosition = 1, kQuaternion = 2, kRaw = 3;
constexpr std::size_t kTimeLength = 5, kPositionLength = 7, kQuaternionLength = 8, kRawLength = 8;
constexpr std::uint8_t kRawLast = 0x80;
constexpr std::array<double, 3> kRawUnit = {1e-3, 1e-2, 1e-2};  // rad/s, m/s², µT per count
constexpr std::array<std::uint32_t, 3> kRawFlag = {kHasGyro, kHasAccel, kHasMag};
constexpr double kQuaternionScale = 32767.0;
constexpr double kMillimetre = 1e-3;
constexpr double kUnitTolerance = 1e-3;

class PosefairCanDecoder final : public CanDecoder {
 public:
  PosefairCanDecoder(std::uint32_t base, bool extended) : base_(base), extended_(extended) {}

  std::string_view protocol() const override { return "posefair-can"; }

  std::vector<CanFilter> filters() const override {
    std::vector<CanFilter> f;
    const std::uint32_t id_mask = extended_ ? CanFrame::kEffMask : CanFrame::kSffMask;
    for (std::uint32_t k = kTime; k <= kRaw; ++k)
      f.push_back({(base_ + k) | (extended_ ? CanFrame::kEffFlag : 0u), id_mask | CanFrame::kEffFlag | CanFrame::kRtrFlag});
    return f;
  }

  void reset() override {
    set_ = {};
    raw_ = {};
    last_time_ = {};
    time_.reset();
    seq_.reset();
  }

 protected:
  bool reads(const CanFrame& f) const override {
    return f.extended() == extended_ && f.id() >= base_ && f.id() - base_ <= kRaw;
  }

  void decode(const CanFrame& f, DecodedSink& sink) override {
    const std::uint32_t kind = f.id() - base_;
    if (kind == kQuaternion) {
      quaternion(f, sink);
      return;
    }
    if (kind == kRaw) {
      raw(f, sink);
      return;
    }
    const std::size_t expected = kind == kTime ? kTimeLength : kPositionLength;
    if (f.len != expected) {
      malformed(f.len);
      return;
    }
    const std::uint8_t seq = f.data[0];
    if (set_.open && (seq != set_.seq || (kind == kTime ? set_.has_time : set_.has_position))) drop_set();
    set_.open = true;
    set_.seq = seq;
    set_.bytes += f.len;
    ++counters_.frames;
    if (kind == kTime) {
      set_.has_time = true;
      set_.time_us = time_.update(bytes::le_u32(&f.data[1]));
      last_time_ = {true, seq, set_.time_us};
    } else {
      set_.has_position = true;
      set_.position = Vec3(bytes::le_i16(&f.data[1]), bytes::le_i16(&f.data[3]), bytes::le_i16(&f.data[5])) * kMillimetre;
    }
  }

 private:
  struct PendingSet {
    bool open = false;
    std::uint8_t seq = 0;
    bool has_time = false;
    bool has_position = false;
    std::uint64_t time_us = 0;
    Vec3 position = Vec3::Zero();
    std::uint64_t bytes = 0;
  };

  struct RawSet {
    bool open = false;
    std::uint8_t seq = 0;
    std::uint32_t flags = 0;  // kHasGyro, kHasAccel, kHasMag received
    Vec3 v[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    std::uint64_t bytes = 0;
  };
  struct LastTime {
    bool valid = false;
    std::uint8_t seq = 0;
    std::uint64_t time_us = 0;
  };

  void raw(const CanFrame& f, DecodedSink& sink) {
    const std::uint8_t kind = f.len == kRawLength ? f.data[1] : 0xFF;
    const std::size_t k = kind & 0x03u;
    if ((kind & 0x7Cu) != 0 || k > 2) {
      malformed(f.len);
      return;
    }
    const std::uint8_t seq = f.data[0];
    if (raw_.open && (seq != raw_.seq || (raw_.flags & kRawFlag[k]) != 0)) {
      ++counters_.resyncs;
      counters_.skipped_bytes += raw_.bytes;
      raw_ = {};
    }
    raw_.open = true;
    raw_.seq = seq;
    raw_.bytes += f.len;
    raw_.flags |= kRawFlag[k];
    raw_.v[k] = Vec3(bytes::le_i16(&f.data[2]), bytes::le_i16(&f.data[4]), bytes::le_i16(&f.data[6])) * kRawUnit[k];
    ++counters_.frames;
    if ((kind & kRawLast) == 0) return;

    DecodedSample s;
    s.flags = kNoOrientation | raw_.flags;
    s.gyro = raw_.v[0];
    s.accel = raw_.v[1];
    s.mag = raw_.v[2];
    s.frame_counter = seq_.update(seq);
    s.has_frame_counter = true;
    if (last_time_.valid && last_time_.seq == seq) {
      s.flags |= kHasDeviceTime;
      s.device_time = static_cast<double>(last_time_.time_us) * 1e-6;
    }
    if (set_.open && set_.seq == seq) set_ = {};  // a raw-only tracker's TIME frame: taken
    raw_ = {};
    ++counters_.samples;
    sink.on_sample(s);
  }

  void malformed(std::size_t len) {
    ++counters_.malformed;
    counters_.skipped_bytes += len;
  }

  void drop_set() {
    ++counters_.resyncs;
    counters_.skipped_bytes += set_.bytes;
    set_ = {};
  }

  void quaternion(const CanFrame& f, DecodedSink& sink) {
    std::array<std::int16_t, 4> v{};
    bool ok = f.len == kQuaternionLength;
    for (std::size_t k = 0; ok && k < 4; ++k) {
      v[k] = bytes::le_i16(&f.data[2 * k]);
      ok = v[k] != -32768;
    }
    const Quat q(v[0] / kQuaternionScale, v[1] / kQuaternionScale, v[2] / kQuaternionScale, v[3] / kQuaternionScale);
    const double n = q.norm();
    if (!ok || !(std::abs(n - 1.0) <= kUnitTolerance)) {
      malformed(f.len);
      if (set_.open) drop_set();
      return;
    }
    ++counters_.frames;
    DecodedSample s;
    s.orientation = Quat(q.coeffs() / n);
    if (set_.open) {
      s.frame_counter = seq_.update(set_.seq);
      s.has_frame_counter = true;
      if (set_.has_time) {
        s.flags |= kHasDeviceTime;
        s.device_time = static_cast<double>(set_.time_us) * 1e-6;
      }
      if (set_.has_position) {
        s.flags |= kHasPosition;
        s.position = set_.position;
      }
      set_ = {};
    }
    ++counters_.samples;
    sink.on_sample(s);
  }

  std::uint32_t base_;
  bool extended_;
  PendingSet set_;
  RawSet raw_;
  LastTime last_time_;
  CounterUnwrapper time_{32};
  CounterUnwrapper seq_{8};
};

std::int16_t to_i16(double v, double scale) {
  const double r = std::round(v * scale);
  return static_cast<std::int16_t>(r > 32767.0 ? 32767.0 : (r < -32767.0 ? -32767.0 : r));
}

}  // namespace

namespace {
constexpr std::string_view kIdFormats[] = {"standard", "extended"};
constexpr OptionSpec kOptions[] = {
    {"posefair_base_id", OptionType::IntegerOrString, "0x200", "the base identifier B: frames B, B+1, B+2, B+3"},
    {"posefair_id_format", OptionType::String, "standard", "standard (11-bit) or extended (29-bit) identifiers", kIdFormats},
};
}  // namespace

const CanDecoderEntry kPosefairCanDecoder{"posefair-can", "posefair's own CAN layout: quaternion, time, position and raw IMU frames",
                                          kOptions, make_posefair_can_decoder};

std::unique_ptr<CanDecoder> make_posefair_can_decoder(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  const bool extended = parse_can_id_format_option("posefair_id_format", read.text("posefair_id_format"));
  const std::uint32_t max = (extended ? CanFrame::kEffMask : CanFrame::kSffMask) - kRaw;
  return std::make_unique<PosefairCanDecoder>(parse_can_id_option("posefair_base_id", read.text("posefair_base_id"), max), extended);
}

std::vector<CanFrame> encode_posefair_can(std::uint32_t base_id, bool extended, const Quat& q,
                                          std::optional<std::uint32_t> device_time_us, const Vec3* position,
                                          std::uint8_t sequence, double timestamp) {
  std::vector<CanFrame> frames;
  if (device_time_us) {
    std::array<std::uint8_t, kTimeLength> d{sequence};
    bytes::put_le_u32(&d[1], *device_time_us);
    frames.push_back(CanFrame::make(base_id + kTime, extended, d, timestamp));
  }
  if (position) {
    std::array<std::uint8_t, kPositionLength> d{sequence};
    for (int k = 0; k < 3; ++k)
      bytes::put_le_u16(&d[1 + 2 * k], static_cast<std::uint16_t>(to_i16((*position)[k], 1.0 / kMillimetre)));
    frames.push_back(CanFrame::make(base_id + kPosition, extended, d, timestamp));
  }
  std::array<std::uint8_t, kQuaternionLength> d{};
  const double c[4] = {q.w(), q.x(), q.y(), q.z()};
  for (int k = 0; k < 4; ++k) bytes::put_le_u16(&d[2 * k], static_cast<std::uint16_t>(to_i16(c[k], kQuaternionScale)));
  frames.push_back(CanFrame::make(base_id + kQuaternion, extended, d, timestamp));
  return frames;
}

std::vector<CanFrame> encode_posefair_can_raw(std::uint32_t base_id, bool extended, const Vec3* gyro,
                                              const Vec3* accel, const Vec3* mag, std::uint8_t sequence,
                                              double timestamp) {
  std::vector<CanFrame> frames;
  const Vec3* parts[3] = {gyro, accel, mag};
  int last = -1;
  for (int k = 0; k < 3; ++k)
    if (parts[k]) last = k;
  for (int k = 0; k < 3; ++k) {
    if (!parts[k]) continue;
    std::array<std::uint8_t, kRawLength> d{sequence, static_cast<std::uint8_t>(k | (k == last ? kRawLast : 0))};
    for (int i = 0; i < 3; ++i)
      bytes::put_le_u16(&d[2 + 2 * i], static_cast<std::uint16_t>(to_i16((*parts[k])[i], 1.0 / kRawUnit[k])));
    frames.push_back(CanFrame::make(base_id + kRaw, extended, d, timestamp));
  }
  return frames;
}

}  // namespace posefair::drivers
