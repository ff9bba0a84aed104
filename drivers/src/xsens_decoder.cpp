// Xsens MTi series, Xbus protocol, MTData2 message: registry name "xsens".
//
// Reference documents
// - Xsens, "MT Low Level Communication Protocol Documentation", MTi 1/10/100/600-series,
//   document MT0101P, revision 2019.A (Dec 2019; xsens.com, now mtidocs.movella.com): the
//   normative definition of the Xbus message, MTData2 and its data identifiers. The facts this
//   file relies on were checked in the following documents, which restate them:
// - Xsens, "MTi User Manual", document MT0605P.E: 4.5.1 (quaternion output: q_LS rotates a
//   vector from the sensor frame S to the local earth frame L, x_L = q_LS x_S q_LS†), 4.12.3
//   (SampleTimeFine: a 4-byte time stamp of 0.1 ms resolution), 5.3.1 (message structure,
//   checksum), 5.7.1 (all binary data big-endian).
// - Fairchild, FMT1000-series datasheet (the Xsens MTi 1-series module), section 6: table 19
//   (data identifier format bits) and table 20 (an example MTData2 message).
// - Movella/Xsens online documentation, "MT low level communication protocol example"
//   (mtidocs.movella.com/mt-low-level-communication-protocol-example, MTi-G-710): byte-exact
//   messages, among them GoToConfig FA FF 30 00 D1 and an MTData2 message. The unit tests
//   check these examples.
// - The extended length (LEN = 0xFF, then u16): Xsens' XsMessageHeader ("a length of 255
//   means extended length is used"), in the MT SDK sources that MRPT ships.
//
// The message: FA (preamble), FF (bus id), MID, LEN, DATA, CS. LEN = 0xFF announces an
// extended length: a u16 big-endian data length follows. All bytes after the preamble, the
// checksum included, sum to 0 mod 256. MTData2 (MID 0x36) data is a sequence of packets:
// data id (u16 BE), size (u8), payload. The low nibble of a data id selects the number format
// (bits 0-1: 0 float32, 1 fixed point 12.20, 2 fixed point 16.32, 3 float64) and, for
// orientation, the earth frame (bits 2-3: 0 ENU, 4 NED, 8 NWU).
//
// What posefair reads
// - 0x201x Quaternion q0 q1 q2 q3, q0 the scalar. Xsens' q_LS rotates sensor coordinates into
//   the local earth frame: exactly posefair's convention (v_world = q v_sensor q*), so no
//   conjugate. The world frame is the earth frame the device was configured for (ENU by
//   default; NED and NWU ids are accepted as they are). Float32, Fp1220 (signed 32-bit / 2^20)
//   and Float64 are decoded. Fp1632 (48 bits per number) is skipped like an unknown packet:
//   the documents seen do not state its byte order beyond doubt; a message whose only
//   quaternion is Fp1632 counts as ignored. A quaternion whose norm differs from 1 by more
//   than 1e-3, or that is not finite, makes the message malformed; otherwise it is normalised.
//   If a message carries several quaternion packets, the first decodable one is used.
// - Raw inertial data, in the sensor frame S, each 3 numbers in the id's number format (Float32,
//   Fp1220 or Float64; Fp1632 skipped as for the quaternion), MT0101P's units:
//   0x402x Acceleration, m/s² -> accel (kHasAccel); 0x802x RateOfTurn, rad/s -> gyro
//   (kHasGyro); 0xC02x MagneticField, "a.u." (arbitrary units: 1 is the field strength where
//   the device's magnetic field mapping was done) -> mag (kHasMag) in µT = a.u. ·
//   xsens_mag_field (default 50 µT, a mid-latitude field; set the local strength if a fusion
//   stage needs the magnitude, the direction does not depend on it). FreeAcceleration (0x4030),
//   DeltaV (0x4010) and DeltaQ (0x8030) are not readings of the sensors and are not read.
//   They ride with the message's quaternion; a message with raw data but no quaternion (an MTi
//   sends each output at its own rate, or an MTi-1 IMU without a filter) gives a raw-only
//   sample (kNoOrientation). A non-finite reading makes the message malformed.
// - 0x1020 PacketCounter (u16, wraps at 2^16) -> frame_counter, unwrapped.
// - 0x1060 SampleTimeFine (u32, 10 kHz ticks, wraps at 2^32 = 4.97 days) -> device_time in s,
//   unwrapped.
// Unwrapping is forward-only (each step is taken modulo the counter's range), so time never
// decreases; a device restart looks like a rollover (reset() starts afresh). Every valid
// MTData2 message advances the unwrapping, also one without a quaternion: an MTi sends each
// output at its own rate, so many messages carry the counter and time but no orientation.
//
// Device quirks and choices
// - MTi devices always send bus id 0xFF ("master device"); other bus ids (old Xbus Master
//   systems) are not accepted as a frame start, which makes false starts 256 times rarer.
// - Messages other than MTData2 (WakeUp 0x3E, Error 0x42, acknowledgements, Configuration ...)
//   and MTData2 messages without a decodable quaternion or raw reading count as ignored_frames.
// - A data length above 2048 bytes (kMaxData; the eMTS message an MTi sends before it starts
//   measuring is about 1.3 KB, MTData2 messages are far shorter) counts as malformed without
//   waiting for the bytes it announces, so a corrupt extended length never stalls the stream;
//   the preamble is skipped and the search goes on. A message whose packets do not tile its
//   data exactly, or whose counter, time or quaternion packet has the wrong size, is malformed.
// - Resynchronisation: after a bad checksum only the preamble is dropped and the search goes
//   on inside the rejected bytes (a corrupted length must not swallow the next good message).
//   Every byte fed is either part of a message whose checksum matched, or counted in
//   skipped_bytes, or held as the start of an incomplete message.
// - Position outputs (LatLon, PositionEcef) are geodetic, not metres in a local frame: not read.
// - The MTi 1-series' I2C/SPI transport (MTSSP) frames differently and is not handled here.
#include "posefair/drivers/xsens_decoder.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>

#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/checksums.hpp"
#include "posefair/drivers/counter_unwrap.hpp"
#include "frame_feed.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint8_t kPreamble = 0xFA;
constexpr std::uint8_t kBusId = 0xFF;
constexpr std::uint8_t kMtData2 = 0x36;
constexpr std::size_t kMaxData = 2048;
constexpr std::size_t kMaxMessage = 6 + kMaxData + 1;  // extended header, data, checksum
constexpr std::size_t kBufferSize = 4096;
static_assert(kBufferSize > kMaxMessage);

constexpr std::uint16_t kPacketCounter = 0x1020;
constexpr std::uint16_t kSampleTimeFine = 0x1060;
constexpr std::uint16_t kQuaternion = 0x2010;
constexpr std::uint16_t kAcceleration = 0x4020;
constexpr std::uint16_t kRateOfTurn = 0x8020;
constexpr std::uint16_t kMagneticField = 0xC020;
constexpr double kSampleTimeFineHz = 10000.0;
constexpr double kUnitTolerance = 1e-3;

std::uint64_t be_u64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(bytes::be_u32(p)) << 32 | bytes::be_u32(p + 4);
}

class XsensDecoder final : public Decoder {
 public:
  explicit XsensDecoder(double mag_ut_per_au) : mag_ut_per_au_(mag_ut_per_au) {}

  std::string_view protocol() const override { return "xsens"; }

  void feed(std::span<const std::uint8_t> in, DecodedSink& sink) override {
    counters_.bytes += in.size();
    buffer_.feed(in, [&](const std::uint8_t* data, std::size_t held) { return process(data, held, sink); });
  }

  void reset() override {
    buffer_.reset();
    end_resync();
    counter_.reset();
    time_.reset();
  }

 private:
  // Handles every whole message in data[0, held); returns how many bytes it used (the rest
  // is the start of an incomplete message, shorter than kMaxMessage).
  std::size_t process(const std::uint8_t* data, std::size_t held, DecodedSink& sink) {
    std::size_t i = 0;
    while (i < held) {
      const std::uint8_t* p = data + i;
      const std::size_t avail = held - i;
      if (p[0] != kPreamble) {
        const void* next = std::memchr(p, kPreamble, avail);
        const std::size_t k = next ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(next) - p) : avail;
        skip(k);
        i += k;
        continue;
      }
      if (avail < 2) break;
      if (p[1] != kBusId) {
        skip(1);
        ++i;
        continue;
      }
      if (avail < 4) break;
      std::size_t header = 4;
      std::size_t data_len = p[3];
      if (p[3] == 0xFF) {
        if (avail < 6) break;
        header = 6;
        data_len = bytes::be_u16(p + 4);
        if (data_len > kMaxData) {
          ++counters_.malformed;
          skip(1);
          ++i;
          continue;
        }
      }
      const std::size_t total = header + data_len + 1;
      if (avail < total) break;
      if (checksum::sum8({p + 1, total - 1}) != 0) {
        ++counters_.bad_checksum;
        skip(1);
        ++i;
        continue;
      }
      ++counters_.frames;
      end_resync();
      if (p[2] == kMtData2)
        handle_mtdata2({p + header, data_len}, sink);
      else
        ++counters_.ignored_frames;
      i += total;
    }
    return i;
  }

  // One quaternion packet's payload, or nothing for a format posefair does not decode.
  static std::optional<std::array<double, 4>> read_quaternion(std::uint16_t id, const std::uint8_t* d,
                                                             std::size_t size, bool& bad_size) {
    std::array<double, 4> q{};
    switch (id & 0x3) {
      case 0:  // float32
        if (size != 16) break;
        for (int k = 0; k < 4; ++k) q[k] = bytes::be_f32(d + 4 * k);
        return q;
      case 1:  // fixed point 12.20
        if (size != 16) break;
        for (int k = 0; k < 4; ++k)
          q[k] = static_cast<double>(static_cast<std::int32_t>(bytes::be_u32(d + 4 * k))) / 1048576.0;
        return q;
      case 2:  // fixed point 16.32: not decoded (see the comment at the top)
        if (size != 24) break;
        return std::nullopt;
      default:  // float64
        if (size != 32) break;
        for (int k = 0; k < 4; ++k) q[k] = std::bit_cast<double>(be_u64(d + 8 * k));
        return q;
    }
    bad_size = true;
    return std::nullopt;
  }

  // One 3-vector packet's payload, or nothing for Fp1632 (see the quaternion).
  static std::optional<Vec3> read_vector(std::uint16_t id, const std::uint8_t* d, std::size_t size, bool& bad_size) {
    Vec3 v;
    switch (id & 0x3) {
      case 0:
        if (size != 12) break;
        for (int k = 0; k < 3; ++k) v[k] = bytes::be_f32(d + 4 * k);
        return v;
      case 1:
        if (size != 12) break;
        for (int k = 0; k < 3; ++k) v[k] = static_cast<double>(static_cast<std::int32_t>(bytes::be_u32(d + 4 * k))) / 1048576.0;
        return v;
      case 2:
        if (size != 18) break;
        return std::nullopt;
      default:
        if (size != 24) break;
        for (int k = 0; k < 3; ++k) v[k] = std::bit_cast<double>(be_u64(d + 8 * k));
        return v;
    }
    bad_size = true;
    return std::nullopt;
  }

  void handle_mtdata2(std::span<const std::uint8_t> data, DecodedSink& sink) {
    DecodedSample s;
    std::optional<std::uint16_t> counter;
    std::optional<std::uint32_t> time;
    std::optional<std::array<double, 4>> quat;
    std::size_t pos = 0;
    while (pos < data.size()) {
      if (data.size() - pos < 3) {
        ++counters_.malformed;
        return;
      }
      const std::uint16_t id = bytes::be_u16(&data[pos]);
      const std::size_t size = data[pos + 2];
      const std::uint8_t* payload = data.data() + pos + 3;
      if (data.size() - pos - 3 < size) {
        ++counters_.malformed;
        return;
      }
      bool bad_size = false;
      if ((id & 0xFFF0) == kPacketCounter) {
        bad_size = size != 2;
        if (!bad_size) counter = bytes::be_u16(payload);
      } else if ((id & 0xFFF0) == kSampleTimeFine) {
        bad_size = size != 4;
        if (!bad_size) time = bytes::be_u32(payload);
      } else if ((id & 0xFFF0) == kQuaternion && (id & 0xC) != 0xC) {
        std::optional<std::array<double, 4>> q = read_quaternion(id, payload, size, bad_size);
        if (q && !quat) quat = q;
      } else if ((id & 0xFFF0) == kAcceleration) {
        read_raw(kHasAccel, s.accel, 1.0, id, payload, size, bad_size, s.flags);
      } else if ((id & 0xFFF0) == kRateOfTurn) {
        read_raw(kHasGyro, s.gyro, 1.0, id, payload, size, bad_size, s.flags);
      } else if ((id & 0xFFF0) == kMagneticField) {
        read_raw(kHasMag, s.mag, mag_ut_per_au_, id, payload, size, bad_size, s.flags);
      }
      if (bad_size) {
        ++counters_.malformed;
        return;
      }
      pos += 3 + size;
    }

    if (!s.accel.allFinite() || !s.gyro.allFinite() || !s.mag.allFinite()) {
      ++counters_.malformed;
      return;
    }
    if (counter) {
      s.frame_counter = counter_.update(*counter);
      s.has_frame_counter = true;
    }
    if (time) {
      s.device_time = static_cast<double>(time_.update(*time)) / kSampleTimeFineHz;
      s.flags |= kHasDeviceTime;
    }
    if (!quat) {
      if ((s.flags & (kHasAccel | kHasGyro | kHasMag)) == 0) {
        ++counters_.ignored_frames;
        return;
      }
      s.flags |= kNoOrientation;
      ++counters_.samples;
      sink.on_sample(s);
      return;
    }
    const Quat q((*quat)[0], (*quat)[1], (*quat)[2], (*quat)[3]);
    const double n = q.norm();
    if (!std::isfinite(n) || !(std::abs(n - 1.0) <= kUnitTolerance)) {
      ++counters_.malformed;
      return;
    }
    s.orientation = Quat(q.coeffs() / n);
    ++counters_.samples;
    sink.on_sample(s);
  }

  // The first decodable packet of a kind is used, as for the quaternion.
  static void read_raw(std::uint32_t flag, Vec3& into, double scale, std::uint16_t id, const std::uint8_t* payload,
                       std::size_t size, bool& bad_size, std::uint32_t& flags) {
    const std::optional<Vec3> v = read_vector(id, payload, size, bad_size);
    if (!v || (flags & flag) != 0) return;
    into = *v * scale;
    flags |= flag;
  }

  const double mag_ut_per_au_;
  detail::MessageBuffer<kBufferSize> buffer_;
  CounterUnwrapper counter_{16};
  CounterUnwrapper time_{32};
};

}  // namespace

namespace {
constexpr OptionSpec kOptions[] = {
    {"xsens_mag_field", OptionType::Float, "50.0",
     "µT that one arbitrary unit of the MagneticField output stands for (the field strength where the magnetic field mapping was done)"},
};
}  // namespace

const DecoderEntry kXsensDecoder{"xsens", "Xsens MTi series over a UART: Xbus MTData2 with a quaternion, acceleration, rate of turn, magnetic field",
                                 kOptions, make_xsens_decoder};

std::unique_ptr<Decoder> make_xsens_decoder(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  const double field = read.real("xsens_mag_field");
  if (!(field > 0.0 && field < 1000.0)) throw OptionError("xsens_mag_field", "must be a field strength in µT, above 0 and below 1000");
  return std::make_unique<XsensDecoder>(field);
}

std::vector<std::uint8_t> encode_xsens_mtdata2(const Quat& q, std::optional<std::uint16_t> packet_counter,
                                               std::optional<std::uint32_t> sample_time_fine,
                                               bool force_extended_length) {
  std::vector<std::uint8_t> data;
  const auto put_id = [&](std::uint16_t id, std::uint8_t size) {
    data.push_back(static_cast<std::uint8_t>(id >> 8));
    data.push_back(static_cast<std::uint8_t>(id));
    data.push_back(size);
  };
  if (packet_counter) {
    put_id(kPacketCounter, 2);
    data.resize(data.size() + 2);
    bytes::put_be_u16(&data[data.size() - 2], *packet_counter);
  }
  if (sample_time_fine) {
    put_id(kSampleTimeFine, 4);
    data.resize(data.size() + 4);
    bytes::put_be_u32(&data[data.size() - 4], *sample_time_fine);
  }
  put_id(kQuaternion, 16);
  for (double v : {q.w(), q.x(), q.y(), q.z()}) {
    data.resize(data.size() + 4);
    bytes::put_be_f32(&data[data.size() - 4], static_cast<float>(v));
  }

  std::vector<std::uint8_t> msg = {kPreamble, kBusId, kMtData2};
  if (force_extended_length || data.size() > 254) {
    msg.push_back(0xFF);
    msg.push_back(static_cast<std::uint8_t>(data.size() >> 8));
    msg.push_back(static_cast<std::uint8_t>(data.size()));
  } else {
    msg.push_back(static_cast<std::uint8_t>(data.size()));
  }
  msg.insert(msg.end(), data.begin(), data.end());
  const std::uint8_t sum = checksum::sum8({msg.data() + 1, msg.size() - 1});
  msg.push_back(static_cast<std::uint8_t>(0x100 - sum));
  return msg;
}

}  // namespace posefair::drivers
