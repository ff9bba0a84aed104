#include "posefair/daemon/wire_protocol.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "posefair/daemon/json_lines.hpp"
#include "posefair/daemon/output_encoder.hpp"

namespace posefair::daemon {
namespace {

// Little-endian byte access, independent of the host's byte order and alignment.
template <typename U>
void put_le(std::uint8_t* p, U v) {
  for (std::size_t i = 0; i < sizeof(U); ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
template <typename U>
U get_le(const std::uint8_t* p) {
  U v = 0;
  for (std::size_t i = 0; i < sizeof(U); ++i) v |= static_cast<U>(static_cast<U>(p[i]) << (8 * i));
  return v;
}
void put_f64(std::uint8_t* p, double v) { put_le<std::uint64_t>(p, std::bit_cast<std::uint64_t>(v)); }
double get_f64(const std::uint8_t* p) { return std::bit_cast<double>(get_le<std::uint64_t>(p)); }

std::uint16_t wire_flags(const PoseMessage& m) {
  std::uint16_t f = static_cast<std::uint16_t>(m.flags & ~kPresenceFlags);
  if (m.position) f |= kFlagPosition;
  if (m.angular_velocity) f |= kFlagAngularVelocity;
  return f;
}

bool finite3(const std::optional<Vec3>& v) { return !v || v->allFinite(); }

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool same_bits(const std::optional<Vec3>& a, const std::optional<Vec3>& b) {
  if (a.has_value() != b.has_value()) return false;
  if (!a) return true;
  for (int i = 0; i < 3; ++i)
    if (!same_bits((*a)[i], (*b)[i])) return false;
  return true;
}

}  // namespace

std::string_view to_string(DecodeError e) {
  switch (e) {
    case DecodeError::kNone: return "ok";
    case DecodeError::kTooShort: return "too-short";
    case DecodeError::kOversized: return "oversized";
    case DecodeError::kBadMagic: return "bad-magic";
    case DecodeError::kUnsupportedVersion: return "bad-version";
    case DecodeError::kBadHeaderLength: return "bad-header-length";
    case DecodeError::kLengthMismatch: return "length-mismatch";
    case DecodeError::kUnknownFlags: return "unknown-flags";
    case DecodeError::kNonFinite: return "non-finite";
    case DecodeError::kBadQuaternion: return "bad-quaternion";
    case DecodeError::kJsonSyntax: return "json-syntax";
    case DecodeError::kJsonSchema: return "json-schema";
  }
  return "unknown";
}

std::size_t payload_size(std::uint16_t flags) {
  std::size_t n = 4 * sizeof(double);
  if (flags & kFlagPosition) n += 3 * sizeof(double);
  if (flags & kFlagAngularVelocity) n += 3 * sizeof(double);
  return n;
}

std::size_t encoded_size(const PoseMessage& m) { return kWireHeaderSize + payload_size(wire_flags(m)); }

std::size_t encode_binary(const PoseMessage& m, std::span<std::uint8_t> out) {
  const std::uint16_t flags = wire_flags(m);
  const std::size_t n = kWireHeaderSize + payload_size(flags);
  if (out.size() < n) throw std::length_error("encode_binary: output buffer too small");
  std::uint8_t* p = out.data();
  std::fill(p, p + kWireHeaderSize, std::uint8_t{0});  // reserved bytes are zero
  std::copy(kWireMagic.begin(), kWireMagic.end(), p + wire_offset::kMagic);
  p[wire_offset::kVersion] = kWireVersion;
  p[wire_offset::kHeaderLength] = static_cast<std::uint8_t>(kWireHeaderSize);
  put_le<std::uint16_t>(p + wire_offset::kFlags, flags);
  put_le<std::uint32_t>(p + wire_offset::kSession, m.session);
  put_le<std::uint32_t>(p + wire_offset::kStream, m.stream);
  put_le<std::uint64_t>(p + wire_offset::kSequence, m.sequence);
  put_f64(p + wire_offset::kSampleTime, m.sample_time);
  put_f64(p + wire_offset::kSendTime, m.send_time);
  std::uint8_t* q = p + kWireHeaderSize;
  for (double v : {m.orientation.w(), m.orientation.x(), m.orientation.y(), m.orientation.z()}) {
    put_f64(q, v);
    q += 8;
  }
  for (const auto* opt : {&m.position, &m.angular_velocity}) {
    if (!*opt) continue;
    for (int i = 0; i < 3; ++i) {
      put_f64(q, (**opt)[i]);
      q += 8;
    }
  }
  return n;
}

std::vector<std::uint8_t> encode_binary(const PoseMessage& m) {
  std::vector<std::uint8_t> out(encoded_size(m));
  encode_binary(m, out);
  return out;
}

DecodeError validate(const PoseMessage& m) {
  if ((m.flags & ~kKnownFlags) != 0) return DecodeError::kUnknownFlags;
  if (!std::isfinite(m.sample_time) || !std::isfinite(m.send_time) || !m.orientation.coeffs().allFinite() ||
      !finite3(m.position) || !finite3(m.angular_velocity))
    return DecodeError::kNonFinite;
  if (!(std::abs(m.orientation.norm() - 1.0) <= kMaxQuaternionNormError)) return DecodeError::kBadQuaternion;
  return DecodeError::kNone;
}

DecodeResult decode_binary(std::span<const std::uint8_t> d) {
  auto fail = [](DecodeError e) { return rejected(e, WireEncoding::kBinary); };
  const std::size_t n = d.size();
  // The order of the checks is part of the specification (docs/protocol.md, "Decoding").
  if (n > kMaxDatagramSize) return fail(DecodeError::kOversized);
  if (n < kWireMagic.size()) return fail(DecodeError::kTooShort);
  if (!std::equal(kWireMagic.begin(), kWireMagic.end(), d.begin())) return fail(DecodeError::kBadMagic);
  if (n <= wire_offset::kVersion) return fail(DecodeError::kTooShort);
  if (d[wire_offset::kVersion] != kWireVersion) return fail(DecodeError::kUnsupportedVersion);
  if (n < kWireHeaderSize) return fail(DecodeError::kTooShort);
  const std::size_t header_length = d[wire_offset::kHeaderLength];
  if (header_length < kWireHeaderSize) return fail(DecodeError::kBadHeaderLength);
  const std::uint8_t* p = d.data();
  const auto flags = get_le<std::uint16_t>(p + wire_offset::kFlags);
  if ((flags & ~kKnownFlags) != 0) return fail(DecodeError::kUnknownFlags);
  if (n != header_length + payload_size(flags)) return fail(DecodeError::kLengthMismatch);

  DecodeResult r;
  r.encoding = WireEncoding::kBinary;
  PoseMessage& m = r.message;
  m.flags = flags;
  m.session = get_le<std::uint32_t>(p + wire_offset::kSession);
  m.stream = get_le<std::uint32_t>(p + wire_offset::kStream);
  m.sequence = get_le<std::uint64_t>(p + wire_offset::kSequence);
  m.sample_time = get_f64(p + wire_offset::kSampleTime);
  m.send_time = get_f64(p + wire_offset::kSendTime);
  const std::uint8_t* q = p + header_length;  // a longer (later v1) header is skipped
  m.orientation = Quat(get_f64(q), get_f64(q + 8), get_f64(q + 16), get_f64(q + 24));
  q += 32;
  auto vec = [&q] {
    Vec3 v(get_f64(q), get_f64(q + 8), get_f64(q + 16));
    q += 24;
    return v;
  };
  if (flags & kFlagPosition) m.position = vec();
  if (flags & kFlagAngularVelocity) m.angular_velocity = vec();
  const DecodeError e = validate(m);
  if (e != DecodeError::kNone) return fail(e);
  return r;
}

DecodeResult decode_datagram(std::span<const std::uint8_t> d) {
  if (!d.empty() && d[0] == '{') return decode_json(d);
  return decode_binary(d);
}

bool bitwise_equal(const PoseMessage& a, const PoseMessage& b) {
  return a.session == b.session && a.stream == b.stream && a.sequence == b.sequence && a.flags == b.flags &&
         same_bits(a.sample_time, b.sample_time) && same_bits(a.send_time, b.send_time) &&
         same_bits(a.orientation.w(), b.orientation.w()) && same_bits(a.orientation.x(), b.orientation.x()) &&
         same_bits(a.orientation.y(), b.orientation.y()) && same_bits(a.orientation.z(), b.orientation.z()) &&
         same_bits(a.position, b.position) && same_bits(a.angular_velocity, b.angular_velocity);
}

namespace {

// [[output]] encoding = "binary": the v1 datagram, written into the publisher's buffer.
class BinaryOutputEncoder final : public OutputEncoder {
 public:
  std::string_view name() const override { return "binary"; }
  std::size_t encode(const PoseMessage& m, std::span<std::uint8_t> out) const override { return encode_binary(m, out); }
};

}  // namespace

// Registered in output_encoder_registry.cpp. No options: every binary output shares one encoder.
const OutputEncoderEntry& binary_output_encoding() {
  static const OutputEncoderEntry entry{
      "binary", "wire protocol v1: one little-endian binary datagram per pose", {},
      [](const posefair::OptionMap& options, std::span<const OutputStream>) -> std::shared_ptr<const OutputEncoder> {
        (void)posefair::OptionReader({}, options);  // it reads none: refuses any
        static const auto encoder = std::make_shared<const BinaryOutputEncoder>();
        return encoder;
      }};
  return entry;
}

}  // namespace posefair::daemon
