// VectorNav ASCII asynchronous outputs, registry name "vectornav".
//
// Reference documents (facts only; no code taken from them):
//  - VN-100 User Manual, UM001, firmware v2.1.0.0, document revision 2.22, VectorNav
//    Technologies (read as the page copies on manualshive.com, "vectornav/vn-100/3752294"):
//    §3.8 Checksum/CRC, §4.7.2 YawPitchRoll, §4.7.3 Quaternion, §5.2.7 Async Data Output Type
//    Register (register 6), §7.2 register examples.
//  - VN-200 User Manual, UM004 (same site, "vectornav/vn-200/3751189"): §3.2 Checksum/CRC,
//    §5.11 Communication Protocol Control (register 30: SerialCount, SerialChecksum).
//  - The same register tables with example responses are reproduced in the Orolia/Safran
//    VersaSync User Manual, appendix 5.3.4 (ASCII outputs of its VectorNav VN-300).
//  - VectorNav Programming Library v1.1 (vn/protocol/uart.h, enum AsciiAsync) for the register-6
//    values: VNYPR = 1, VNQTN = 2, VNQMR = 8, VNYMR = 14.
//
// Sentences: "$VNxxx,f1,...,fn*CS\r\n". CS is "an XOR of all bytes between, but not including,
// the dollar sign ($) and asterisk (*)" printed as two hex digits, or, when register 30 selects
// it, a CRC16-CCITT printed as four hex digits (UM001 §3.8.2/§3.8.3; the manual's C routine is
// the byte-wise form of CRC-16 polynomial 0x1021, init 0, no reflection: CRC-16/XMODEM, which is
// checksum::crc16_ccitt(…, 0)). With register 30's SerialCount set, the device appends a
// counter field "preceded by the T character" just before the checksum (UM004 §5.11.1, example
// "$VNYPR,+010.071,+000.278,-002.026,T1162704*2F"); SerialStatus appends a status field the
// same way. Up to two such trailing fields starting with 'T' or 'S' are accepted and not read.
//
// Outputs decoded (any other valid sentence, e.g. $VNINS, $VNRRG/$VNWRG
// responses, $VNERR, counts as ignored_frames):
//  - VNQMR (register 15): quaternion x, y, z, w ("Quat[3] ... Scalar component"), magnetic,
//    acceleration, angular rate: 13 numbers.      - VNQTN (register 9): the quaternion alone.
//  - VNYMR (register 27): yaw, pitch, roll in degrees, magnetic, acceleration, angular rate: 12
//    numbers.                                       - VNYPR (register 8): the three angles alone.
// The brief asked for VNQMR and VNYMR; VNQTN and VNYPR carry the same attitude in the same
// conventions, so a device left at ADOR 1 or 2 works too.
//
// Raw inertial readings (UM001 §7.2.4-§7.2.8, §6.1.1; units as the tables give them): the
// magnetic field in Gauss (µT = 100 · Gauss), acceleration in m/s², angular rate in rad/s, all
// in the body frame. VNQMR and VNYMR carry the compensated ones beside the attitude: the
// sample has both. Sentences with readings and no attitude give a raw-only sample
// (kNoOrientation):
//  - VNMAR (register 20): magnetic, acceleration, angular rate (compensated): 9 numbers;
//  - VNIMU (register 54): the uncompensated magnetic, acceleration, angular rate, then
//    temperature and pressure (not read): 11 numbers;
//  - VNMAG, VNACC, VNGYR (registers 17, 18, 19): one of the three: 3 numbers.
// Values must be finite; the readings are not range-checked (a saturated sensor is the fusion
// stage's to judge).
//
// Conventions. posefair's sample q rotates sensor coordinates into world coordinates,
// v_world = q v_sensor q*. VectorNav's world frame is the local North-East-Down frame and its
// sensor frame is the body frame: "The attitude is given as a 3,2,1 Euler angle sequence
// describing the body frame with respect to the local North East Down (NED) frame" (§4.7.2);
// "The last term is the scalar value. The attitude is given as the body frame with respect to
// the local North East Down (NED) frame" (§4.7.3); the DCM "maps vectors from the North East
// Down (NED) frame into the body frame" (§4.7.4), i.e. DCM = R(q)ᵀ.
//  - Quaternion: the four numbers (x, y, z, w) are the components of the Hamilton quaternion of
//    the body→NED rotation, so posefair's q = (w, x, y, z) with NO conjugate. Checked against
//    the manual's own example pairs, recorded one after the other on one sensor: register 8
//    (yaw 6.271°, pitch 0.031°, roll -2.000°) with register 9 (-0.017386, -0.000303, +0.055490,
//    +0.998308), and register 27 with register 15: read this way each pair agrees to about 0.1°
//    (including the sign of the small second-order y term); with a conjugate they would
//    disagree by twice the yaw. The tests assert both.
//  - Yaw, pitch, roll: a 3-2-1 (Z-Y-X) intrinsic sequence: R = Rz(yaw) · Ry(pitch) · Rx(roll),
//    body→NED. That is euler_to_quat({Z, Y, X}, {yaw, pitch, roll}) (euler_angles.hpp composes
//    R_axes[0](a0) · R_axes[1](a1) · R_axes[2](a2)), reused here. So yaw 90° alone turns the
//    body x axis (forward) onto NED y (east); pitch 90° alone turns it onto -z (up).
//
// Framing and counting choices.
//  - A sentence runs from '$' to '\n' (a '\r' before the '\n' is dropped). A '$' inside a
//    sentence starts a new one (the device lost bytes; the partial one is skipped); a byte that
//    is neither printable ASCII nor '\r' ends the partial sentence as garbage. A sentence longer
//    than kVectorNavMaxSentence (256 bytes from '$' through '\n'; the VectorNav library's own
//    default UART buffer is 256 bytes and the longest ASCII output is well under it) is
//    discarded as soon as it exceeds the bound: memory stays bounded whatever the input.
//    Discarded partial sentences and bytes between sentences count in skipped_bytes, each run
//    of them as one resync.
//  - A complete sentence whose checksum field is missing, is not 2 or 4 hex digits, or does
//    not match counts as bad_checksum. A matching one counts as a frame; its contents must then
//    be plausible or it counts as malformed: exactly the expected count of numbers (plus at most
//    two 'T'/'S' fields), all finite; angles within ±180° (yaw, roll) and ±90° (pitch); a
//    quaternion norm within 1e-3 of 1 (the device prints 6 decimals: its own error is ~1e-6),
//    then normalised.
//  - Checksum "XX" (or "XXXX"): UM001 §3.8.1 calls this the checksum bypass, and register 30's
//    SerialChecksum can switch checksums off. Default ("reject"): such a sentence counts as
//    bad_checksum and gives no sample: an unchecked sentence with one flipped digit is a wrong
//    attitude that no later stage can detect, and the factory configuration (and every example
//    in the manuals) carries a checksum. The failure is loud, not silent: a sensor configured
//    without checksums shows bad_checksum rising with frames at 0. The remedy is to re-enable
//    the checksum in register 30 (preferably the CRC-16), or, knowingly, set
//    vectornav_unchecked = "accept": unchecked sentences are then used (and counted as frames)
//    after the checks above plus a strict number format (sign, digits, '.', digits, as the
//    device prints), which catches many but not all corruptions.
#include "posefair/drivers/vectornav_decoder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <span>
#include <stdexcept>
#include <string_view>

#include "posefair/core/euler_angles.hpp"
#include "posefair/drivers/checksums.hpp"
#include "posefair/formats/format_detail.hpp"

namespace posefair::drivers {

namespace {

constexpr double kUnitTolerance = 1e-3;
constexpr std::size_t kMaxNumbers = 13;

constexpr double kMicroteslaPerGauss = 100.0;

enum class Attitude { kQuaternion, kYawPitchRoll, kNone };

// Each output read: its header, how many numbers it has, its attitude, and where its magnetic,
// acceleration and angular rate triples start (-1: not in it).
struct Output {
  std::string_view header;
  std::size_t numbers;
  Attitude attitude;
  int mag, accel, gyro;
};

constexpr Output kOutputs[] = {
    {"VNQMR", 13, Attitude::kQuaternion, 4, 7, 10},  {"VNYMR", 12, Attitude::kYawPitchRoll, 3, 6, 9},
    {"VNQTN", 4, Attitude::kQuaternion, -1, -1, -1}, {"VNYPR", 3, Attitude::kYawPitchRoll, -1, -1, -1},
    {"VNMAR", 9, Attitude::kNone, 0, 3, 6},          {"VNIMU", 11, Attitude::kNone, 0, 3, 6},
    {"VNMAG", 3, Attitude::kNone, 0, -1, -1},        {"VNACC", 3, Attitude::kNone, -1, 0, -1},
    {"VNGYR", 3, Attitude::kNone, -1, -1, 0},
};

const Output* output_of(std::string_view header) {
  for (const Output& o : kOutputs)
    if (o.header == header) return &o;
  return nullptr;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// The device's own number format: a sign, digits, '.', digits ("+006.380", "-0.017057").
bool device_number_format(std::string_view f) {
  if (f.size() < 4 || (f[0] != '+' && f[0] != '-')) return false;
  std::size_t i = 1;
  while (i < f.size() && is_digit(f[i])) ++i;
  if (i == 1 || i >= f.size() || f[i] != '.') return false;
  const std::size_t frac = ++i;
  while (i < f.size() && is_digit(f[i])) ++i;
  return i == f.size() && i > frac;
}

std::span<const std::uint8_t> as_bytes(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

class VectorNavDecoder final : public Decoder {
 public:
  explicit VectorNavDecoder(bool accept_unchecked) : accept_unchecked_(accept_unchecked) {}

  std::string_view protocol() const override { return "vectornav"; }

  void feed(std::span<const std::uint8_t> bytes, DecodedSink& sink) override {
    counters_.bytes += bytes.size();
    const std::uint8_t* p = bytes.data();
    const std::uint8_t* const end = p + bytes.size();
    while (p < end) {
      if (len_ == 0) {  // hunting for '$'
        const void* dollar = std::memchr(p, '$', static_cast<std::size_t>(end - p));
        if (dollar == nullptr) {
          skip(static_cast<std::size_t>(end - p));
          return;
        }
        const auto* d = static_cast<const std::uint8_t*>(dollar);
        skip(static_cast<std::size_t>(d - p));
        start_sentence();
        p = d + 1;
        continue;
      }
      while (p < end) {  // inside a sentence
        const std::uint8_t c = *p++;
        if (c == '\n') {
          finish_sentence(sink);
          len_ = 0;
          break;
        }
        if (c == '$') {  // the partial sentence lost its end: start over here
          skip(len_);
          start_sentence();
          continue;
        }
        if ((c < 0x20 && c != '\r') || c > 0x7E || len_ + 1 >= kVectorNavMaxSentence) {
          skip(len_ + 1);  // not a sentence byte, or no '\n' within the bound
          len_ = 0;
          break;
        }
        buf_[len_++] = static_cast<char>(c);
      }
    }
  }

  void reset() override {
    skip(len_);
    len_ = 0;
    end_resync();
  }

 private:
  void start_sentence() {
    end_resync();
    buf_[0] = '$';
    len_ = 1;
  }

  // buf_[0, len_) is "$...", the '\n' already consumed.
  void finish_sentence(DecodedSink& sink) {
    std::string_view s(buf_.data(), len_);
    if (s.back() == '\r') s.remove_suffix(1);
    std::size_t digits = 0;
    if (s.size() >= 4 && s[s.size() - 3] == '*') {
      digits = 2;
    } else if (s.size() >= 6 && s[s.size() - 5] == '*') {
      digits = 4;
    } else {
      ++counters_.bad_checksum;
      return;
    }
    const std::string_view body = s.substr(1, s.size() - digits - 2);
    const std::string_view field = s.substr(s.size() - digits);
    const bool unchecked = field == std::string_view("XXXX").substr(0, digits);
    if (unchecked) {
      if (!accept_unchecked_) {
        ++counters_.bad_checksum;
        return;
      }
    } else {
      std::uint32_t given = 0;
      for (const char c : field) {
        const int v = hex_value(c);
        if (v < 0) {
          ++counters_.bad_checksum;
          return;
        }
        given = given << 4 | static_cast<std::uint32_t>(v);
      }
      const std::uint32_t computed = digits == 2 ? checksum::xor8(as_bytes(body))
                                                 : checksum::crc16_ccitt(as_bytes(body), 0);
      if (given != computed) {
        ++counters_.bad_checksum;
        return;
      }
    }
    ++counters_.frames;
    decode(body, unchecked, sink);
  }

  void decode(std::string_view body, bool strict, DecodedSink& sink) {
    const std::size_t comma = body.find(',');
    const Output* const out = output_of(body.substr(0, comma));
    if (out == nullptr) {
      ++counters_.ignored_frames;
      return;
    }
    const std::size_t expected = out->numbers;
    std::array<double, kMaxNumbers> v{};
    std::size_t count = 0;
    std::size_t extras = 0;
    std::size_t i = comma == std::string_view::npos ? body.size() : comma;
    while (i < body.size()) {  // body[i] == ','
      const std::size_t start = i + 1;
      std::size_t stop = body.find(',', start);
      if (stop == std::string_view::npos) stop = body.size();
      const std::string_view f = body.substr(start, stop - start);
      if (count < expected) {
        const std::optional<double> x = formats::detail::parse_number(f);
        if (!x || !std::isfinite(*x) || (strict && !device_number_format(f))) return malformed();
        v[count++] = *x;
      } else if (f.empty() || (f[0] != 'T' && f[0] != 'S') || ++extras > 2) {
        return malformed();
      }
      i = stop;
    }
    if (count < expected) return malformed();

    DecodedSample sample;
    if (out->attitude == Attitude::kQuaternion) {
      Quat q(v[3], v[0], v[1], v[2]);  // scalar last on the wire
      const double norm = q.norm();
      if (!(std::abs(norm - 1.0) <= kUnitTolerance)) return malformed();
      q.coeffs() /= norm;
      sample.orientation = q;
    } else if (out->attitude == Attitude::kYawPitchRoll) {
      if (!(std::abs(v[0]) <= 180.0 && std::abs(v[1]) <= 90.0 && std::abs(v[2]) <= 180.0)) return malformed();
      static constexpr std::array<Axis, 3> kZyx = {Axis::Z, Axis::Y, Axis::X};
      const std::array<double, 3> ypr = {v[0], v[1], v[2]};
      sample.orientation = euler_to_quat(kZyx, ypr);
    } else {
      sample.flags |= kNoOrientation;
    }
    const auto triple = [&](int at) { return Vec3(v[at], v[at + 1], v[at + 2]); };
    if (out->mag >= 0) {
      sample.mag = triple(out->mag) * kMicroteslaPerGauss;
      sample.flags |= kHasMag;
    }
    if (out->accel >= 0) {
      sample.accel = triple(out->accel);
      sample.flags |= kHasAccel;
    }
    if (out->gyro >= 0) {
      sample.gyro = triple(out->gyro);
      sample.flags |= kHasGyro;
    }
    ++counters_.samples;
    sink.on_sample(sample);
  }

  void malformed() { ++counters_.malformed; }

  std::array<char, kVectorNavMaxSentence> buf_{};
  std::size_t len_ = 0;  // 0 while hunting for '$'
  bool accept_unchecked_;
};

std::string sentence(const std::string& body, bool crc16) {
  return "$" + body + "*" + vectornav_checksum(body, crc16) + "\r\n";
}

void append(std::string& s, const char* format, double v) {
  char buffer[64];
  const int n = std::snprintf(buffer, sizeof buffer, format, v);
  s += ',';
  if (n > 0) s.append(buffer, std::min<std::size_t>(static_cast<std::size_t>(n), sizeof buffer - 1));
}

// Magnetic (Gauss), acceleration (m/s²) and angular rate (rad/s) of the manual's example
// responses, formatted as the device prints them.
void append_mag_accel_gyro(std::string& s) {
  for (const double m : {1.0640, -0.2531, 3.0614}) append(s, "%+.4f", m);
  for (const double a : {0.005, 0.344, -9.758}) append(s, "%+07.3f", a);
  for (const double g : {-0.001222, -0.000450, -0.001218}) append(s, "%+.6f", g);
}

}  // namespace

namespace {
constexpr std::string_view kUncheckedChoices[] = {"reject", "accept"};
constexpr OptionSpec kOptions[] = {
    {"vectornav_unchecked", OptionType::String, "reject",
     "sentences with checksum XX (checksums off on the device): reject (count as bad_checksum) or accept",
     kUncheckedChoices},
};
}  // namespace

const DecoderEntry kVectorNavDecoder{"vectornav", "VectorNav VN-100/200/300 ASCII: $VNQMR, $VNYMR and kin, with $VNMAR/$VNIMU raw readings", kOptions,
                                     make_vectornav_decoder};

std::unique_ptr<Decoder> make_vectornav_decoder(const OptionMap& options) {
  const OptionReader read(kOptions, options);
  const std::string unchecked = read.text("vectornav_unchecked");
  if (unchecked == "reject") return std::make_unique<VectorNavDecoder>(false);
  if (unchecked == "accept") return std::make_unique<VectorNavDecoder>(true);
  throw OptionError("vectornav_unchecked", "expected \"reject\" or \"accept\", got \"" + unchecked + "\"");
}

std::string vectornav_checksum(const std::string& body, bool crc16) {
  char buffer[8];
  if (crc16) {
    std::snprintf(buffer, sizeof buffer, "%04X", static_cast<unsigned>(checksum::crc16_ccitt(as_bytes(body), 0)));
  } else {
    std::snprintf(buffer, sizeof buffer, "%02X", static_cast<unsigned>(checksum::xor8(as_bytes(body))));
  }
  return buffer;
}

std::string encode_vectornav_vnqmr(const Quat& q, bool crc16) {
  std::string body = "VNQMR";
  for (const double c : {q.x(), q.y(), q.z(), q.w()}) append(body, "%+.6f", c);
  append_mag_accel_gyro(body);
  return sentence(body, crc16);
}

std::string encode_vectornav_vnymr(double yaw_deg, double pitch_deg, double roll_deg, bool crc16) {
  std::string body = "VNYMR";
  for (const double a : {yaw_deg, pitch_deg, roll_deg}) append(body, "%+08.3f", a);
  append_mag_accel_gyro(body);
  return sentence(body, crc16);
}

}  // namespace posefair::drivers
