// CEVA / Hillcrest Labs BNO080, BNO085, BNO086 in UART-RVC mode ("bno08x-rvc").
//
// Reference document: "BNO080 Datasheet", document 1000-3927, October 2017, Hillcrest
// Laboratories, Inc. (www.hillcrestlabs.com; the copy distributed with SparkFun's BNO080 Qwiic
// board): Figure 1-5 (PS1 = 0, PS0 = 1 selects UART-RVC), 1.3.5.1 "UART-RVC operation" (115200
// b/s 8N1), 1.3.5.2 "UART-RVC protocol" (Figure 1-25), and 5.1 "BNO080 in UART-RVC mode".
// CEVA's later "BNO080/85/86 Datasheet" (revision 1.11, 2021) keeps the same section. CEVA's
// application note 1000-4045 ("UART-RVC for the BNO08X") was not available to me; nothing
// here depends on it.
//
// The frame (19 bytes, 100 Hz, 115200 baud 8N1, the BNO08x only transmits):
//   0xAA 0xAA | index u8 | yaw, pitch, roll int16 LE, 0.01° | x, y, z acceleration int16 LE, mg |
//   3 bytes "reserved, currently set to zero" | checksum
// Checksum: "The Index, yaw, pitch, roll, acceleration and reserved data bytes are added to
// produce the checksum": the low byte of the sum of bytes 2..17 (16 bytes: 1 + 12 + 3, not 13),
// checked against the document's example (see the unit test), whose sum is 0xE7.
//
// Quirks and choices:
//   - Orientation: "Yaw ... rotation around the Z-axis since reset, range +/- 180°; Pitch ...
//     around the Y-axis, +/- 90°; Roll ... around the X-axis, +/- 180°", and "To determine the
//     actual orientation of the module, the rotations should be applied in the order yaw, pitch
//     then roll." I read that as intrinsic z-y'-x'' (aerospace) Tait-Bryan angles, right-handed
//     positive rotations: R(sensor -> world) = Rz(yaw) · Ry(pitch) · Rx(roll) (equivalently,
//     extrinsic roll about X, then pitch about Y, then yaw about Z). euler_to_quat({Z, Y, X}) is
//     exactly that composition and is reused. Yaw is relative to the heading at reset (RVC mode
//     uses no magnetometer), so the world frame's X is wherever the module pointed at reset.
//   - Values outside the documented ranges (|yaw| or |roll| > 180°, |pitch| > 90°) cannot come
//     from the device: such a frame counts as malformed (it usually is garbage whose checksum
//     happened to match).
//   - The three bytes after the accelerations are not checked: zero on the BNO080, but BNO086
//     firmware reports motion intent / motion request there (third-party drivers' reading).
//   - The accelerations ride with the frame's orientation (kHasAccel), in m/s² = mg · 9.80665e-3
//     (standard gravity). They include gravity: the document's example reads (-371, -20, 977)
//     mg, 1.05 g in all, with the module tilted by its roll of 20.85°.
//   - The index counts reports modulo 256; frame_counter is it unwrapped (each step forward is
//     (index - previous) mod 256, so fewer than 256 lost frames in a row are assumed; a repeated
//     index does not advance it). reset() forgets it. There is no device time.
//   - After reset the module prints a text banner ("%Hillcrest Labs ...", document 5.1): that is
//     garbage to this decoder (skipped_bytes, one resync).
//   - Every valid frame is either a sample or malformed. Bytes not part of a valid frame are
//     skipped_bytes; each run of them is one resync. A frame whose checksum fails counts in
//     bad_checksum and the search resumes at its second byte (0xAA bytes in the data, e.g.
//     index 0xAA, may look like a header; a good frame after them is still found).
#include "posefair/drivers/bno08x_rvc_decoder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "posefair/core/euler_angles.hpp"
#include "posefair/drivers/byte_order.hpp"
#include "posefair/drivers/checksums.hpp"
#include "frame_feed.hpp"

namespace posefair::drivers {
namespace {

constexpr std::uint8_t kHeader = 0xAA;
constexpr std::size_t kFrameSize = kBno08xRvcFrameSize;
constexpr std::size_t kSummedFirst = 2;   // the index
constexpr double kMetresPerSecondSquaredPerMilliG = 9.80665e-3;
constexpr std::size_t kSummedCount = 16;  // index, 12 bytes of angles and accelerations, 3 reserved
constexpr std::int16_t kMaxYawRoll = 18000;
constexpr std::int16_t kMaxPitch = 9000;

std::int16_t saturate_i16(double v) {
  const double r = std::round(v);
  if (!(r >= -32768.0)) return -32768;  // also NaN
  if (r > 32767.0) return 32767;
  return static_cast<std::int16_t>(r);
}

class Bno08xRvcDecoder final : public Decoder {
 public:
  std::string_view protocol() const override { return "bno08x-rvc"; }

  void feed(std::span<const std::uint8_t> in, DecodedSink& sink) override {
    counters_.bytes += in.size();
    carry_.feed(in, [&](const std::uint8_t* p, std::size_t n, std::size_t limit) { return scan(p, n, limit, sink); });
  }

  void reset() override {
    carry_.reset();
    end_resync();
    have_index_ = false;
    last_index_ = 0;
    counter_ = 0;
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
      if (f[1] != kHeader) {
        skip(1);
        ++pos;
        continue;
      }
      if (checksum::sum8({f + kSummedFirst, kSummedCount}) != f[kFrameSize - 1]) {
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
    const std::uint8_t index = f[2];
    if (have_index_)
      counter_ += static_cast<std::uint8_t>(index - last_index_);
    else
      counter_ = index;
    have_index_ = true;
    last_index_ = index;

    const std::int16_t yaw = bytes::le_i16(f + 3);
    const std::int16_t pitch = bytes::le_i16(f + 5);
    const std::int16_t roll = bytes::le_i16(f + 7);
    if (yaw > kMaxYawRoll || yaw < -kMaxYawRoll || roll > kMaxYawRoll || roll < -kMaxYawRoll || pitch > kMaxPitch ||
        pitch < -kMaxPitch) {
      ++counters_.malformed;
      return;
    }
    static constexpr std::array<Axis, 3> kZYX = {Axis::Z, Axis::Y, Axis::X};
    const std::array<double, 3> deg = {yaw * 0.01, pitch * 0.01, roll * 0.01};
    DecodedSample s;
    s.orientation = euler_to_quat(kZYX, deg);
    s.accel = Vec3(bytes::le_i16(f + 9), bytes::le_i16(f + 11), bytes::le_i16(f + 13)) * kMetresPerSecondSquaredPerMilliG;
    s.flags = kHasAccel;
    s.frame_counter = counter_;
    s.has_frame_counter = true;
    ++counters_.samples;
    sink.on_sample(s);
  }

  detail::SplitFrameCarry<kFrameSize> carry_;
  bool have_index_ = false;
  std::uint8_t last_index_ = 0;
  std::uint64_t counter_ = 0;
};

}  // namespace

const DecoderEntry kBno08xRvcDecoder{"bno08x-rvc", "CEVA / Hillcrest BNO080, BNO085, BNO086 in UART-RVC mode: yaw, pitch, roll and acceleration",
                                     {}, make_bno08x_rvc_decoder};

std::unique_ptr<Decoder> make_bno08x_rvc_decoder(const OptionMap& options) {
  (void)OptionReader({}, options);  // it reads none: refuses any
  return std::make_unique<Bno08xRvcDecoder>();
}

std::array<std::uint8_t, kBno08xRvcFrameSize> encode_bno08x_rvc(std::uint8_t index, double yaw_deg, double pitch_deg,
                                                                double roll_deg, double accel_x_mg, double accel_y_mg,
                                                                double accel_z_mg,
                                                                const std::array<std::uint8_t, 3>& tail) {
  std::array<std::uint8_t, kBno08xRvcFrameSize> f{};
  f[0] = kHeader;
  f[1] = kHeader;
  f[2] = index;
  const std::array<double, 6> v = {yaw_deg * 100.0, pitch_deg * 100.0, roll_deg * 100.0,
                                   accel_x_mg,      accel_y_mg,        accel_z_mg};
  for (std::size_t i = 0; i < v.size(); ++i)
    bytes::put_le_u16(f.data() + 3 + 2 * i, static_cast<std::uint16_t>(saturate_i16(v[i])));
  std::copy(tail.begin(), tail.end(), f.begin() + 15);
  f[18] = checksum::sum8({f.data() + kSummedFirst, kSummedCount});
  return f;
}

}  // namespace posefair::drivers
