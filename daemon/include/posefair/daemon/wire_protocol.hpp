#pragma once
// The posefair UDP wire protocol, version 1: one pose per datagram, little-endian binary
// ("PFP1") or a JSON line. docs/protocol.md is the normative specification; this file and
// wire_protocol.cpp follow it, and tests/protocol/wire_protocol_test.cpp pins the byte layout
// against hand-written golden bytes so the two cannot drift.
//
// Pure encode/decode: bytes in, messages out. No sockets, no allocation on the binary decode
// path, never reads outside the span it is given, never throws on any input.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair::daemon {

// --- constants (docs/protocol.md, "Binary datagram") ---
inline constexpr std::array<std::uint8_t, 4> kWireMagic = {0x50, 0x46, 0x50, 0x31};  // "PFP1"
inline constexpr std::uint8_t kWireVersion = 1;
inline constexpr std::size_t kWireHeaderSize = 56;     // header length written by v1 senders
inline constexpr std::size_t kMaxDatagramSize = 1500;  // larger datagrams are rejected as oversized
inline constexpr std::uint16_t kDefaultPort = 5700;    // default UDP port of publisher and subscribers
inline constexpr double kMaxQuaternionNormError = 1e-3;  // | |q| - 1 | above this is rejected

// Header byte offsets.
namespace wire_offset {
inline constexpr std::size_t kMagic = 0, kVersion = 4, kHeaderLength = 5, kFlags = 6, kSession = 8, kStream = 12,
                             kSequence = 16, kSampleTime = 24, kSendTime = 32, kReserved = 40;
}

// Flag bits (u16 at offset 6). Bits 0 and 1 say which optional payload fields follow; the
// encoder derives them from PoseMessage::position / angular_velocity.
enum PoseFlag : std::uint16_t {
  kFlagPosition = 1u << 0,         // position x, y, z follows the quaternion
  kFlagAngularVelocity = 1u << 1,  // angular velocity x, y, z (rad/s, body frame) follows
  kFlagClamped = 1u << 2,          // the fairing moved this pose to its ε bound
  kFlagBridged = 1u << 3,          // bridged / interpolated across a gap (reserved for spline bridging)
};
inline constexpr std::uint16_t kKnownFlags = kFlagPosition | kFlagAngularVelocity | kFlagClamped | kFlagBridged;
inline constexpr std::uint16_t kPresenceFlags = kFlagPosition | kFlagAngularVelocity;

// One published pose.
struct PoseMessage {
  std::uint32_t session = 0;   // random per daemon start; a change means the sequence restarted
  std::uint32_t stream = 0;    // stream id
  std::uint64_t sequence = 0;  // per stream, 0 at session start, +1 per pose sent
  double sample_time = 0.0;    // s, the sample's time as the engine used it
  double send_time = 0.0;      // s of CLOCK_REALTIME when sent; 0 = not set
  Quat orientation = Quat::Identity();  // physical rotation sensor→world: v_world = q v q*
  std::optional<Vec3> position;
  std::optional<Vec3> angular_velocity;  // rad/s, body (sensor) frame
  // The flags word. The encoder writes the presence bits (0, 1) from the optionals above and
  // every other bit as given; the decoder returns the word exactly as received.
  std::uint16_t flags = 0;

  bool clamped() const { return (flags & kFlagClamped) != 0; }
  bool bridged() const { return (flags & kFlagBridged) != 0; }
};

// Why a datagram was rejected. Every value is distinct and has a stable name (to_string),
// used in `posefair sub` statistics and in docs/protocol.md.
enum class DecodeError : std::uint8_t {
  kNone = 0,            // "ok"
  kTooShort,            // "too-short": fewer bytes than the header (or than magic/version) needs
  kOversized,           // "oversized": larger than kMaxDatagramSize, or truncated on receipt
  kBadMagic,            // "bad-magic": neither "PFP1" nor a JSON object
  kUnsupportedVersion,  // "bad-version": version is not 1
  kBadHeaderLength,     // "bad-header-length": header length field < 56
  kLengthMismatch,      // "length-mismatch": size != header length + payload length
  kUnknownFlags,        // "unknown-flags": a reserved flag bit (or unknown JSON flag name)
  kNonFinite,           // "non-finite": NaN or ±inf in any number
  kBadQuaternion,       // "bad-quaternion": | |q| - 1 | > 1e-3 (includes q = 0)
  kJsonSyntax,          // "json-syntax": not one well-formed JSON object
  kJsonSchema,          // "json-schema": well-formed, but a member missing, mistyped or out of range
};
inline constexpr std::size_t kDecodeErrorCount = 12;
std::string_view to_string(DecodeError e);

enum class WireEncoding : std::uint8_t { kBinary, kJson };

struct DecodeResult {
  DecodeError error = DecodeError::kNone;
  WireEncoding encoding = WireEncoding::kBinary;
  PoseMessage message;  // meaningful only when ok()
  bool ok() const { return error == DecodeError::kNone; }
  explicit operator bool() const { return ok(); }
};
// A rejection (built in place, so no half-filled message is ever copied).
inline DecodeResult rejected(DecodeError e, WireEncoding encoding) { return DecodeResult{e, encoding, PoseMessage{}}; }

// --- binary v1 ---
// Payload bytes after the header for a flags word: 32 + 24 per presence bit.
std::size_t payload_size(std::uint16_t flags);
// Size of the datagram encode_binary writes for m (56 + payload).
std::size_t encoded_size(const PoseMessage& m);
// Writes the datagram into out and returns the number of bytes written (encoded_size(m)).
// Throws std::length_error if out is too small. Numbers are written bit for bit: the encoder
// does not validate (see validate()) so tests can produce every invalid datagram.
std::size_t encode_binary(const PoseMessage& m, std::span<std::uint8_t> out);
std::vector<std::uint8_t> encode_binary(const PoseMessage& m);
// Decodes one binary v1 datagram; checks in the order listed in docs/protocol.md.
DecodeResult decode_binary(std::span<const std::uint8_t> datagram);

// The semantic checks a decoder applies after parsing (reserved flag bits, non-finite numbers,
// quaternion norm); kNone if m would be accepted. Publishers call this before sending.
DecodeError validate(const PoseMessage& m);

// Either encoding: a datagram whose first byte is '{' is a JSON line, anything else binary.
DecodeResult decode_datagram(std::span<const std::uint8_t> datagram);

// Bit-exact equality (doubles compared by their bits, so NaN == NaN and -0 != +0).
bool bitwise_equal(const PoseMessage& a, const PoseMessage& b);

}  // namespace posefair::daemon
