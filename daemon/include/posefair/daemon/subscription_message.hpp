#pragma once
// The subscription protocol's messages (docs/protocol.md, "Subscribing"): a client asks the
// daemon's control port for streams with SUBSCRIBE, proves it receives at its address by echoing
// the stateless cookie the daemon sends back, and renews or ends its lease. Little-endian binary,
// magic "PFS1". Requests are at least 32 bytes and every reply is exactly 32, so a reply is
// never larger than the request it answers.
//
// Pure encode/decode: bytes in, messages out. No sockets, no clock, never reads outside the span
// it is given, never throws on any input (tests/fuzz/subscription_message_fuzz.cpp).
// The optional pre-shared-key MAC is libsodium's crypto_auth (HMAC-SHA-512-256).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace posefair::daemon {

inline constexpr std::array<std::uint8_t, 4> kSubscriptionMagic = {0x50, 0x46, 0x53, 0x31};  // "PFS1"
inline constexpr std::uint16_t kDefaultControlPort = 5710;
inline constexpr std::size_t kCookieSize = 16;
inline constexpr std::size_t kRequestHeaderSize = 32;
inline constexpr std::size_t kReplySize = 32;
inline constexpr std::size_t kMaxEncodingName = 32;
inline constexpr std::size_t kMaxRequestStreams = 16;
inline constexpr std::size_t kRequestMacSize = 32;  // crypto_auth_BYTES
inline constexpr std::size_t kPskSize = 32;         // crypto_auth_KEYBYTES
using Cookie = std::array<std::uint8_t, kCookieSize>;
using PreSharedKey = std::array<std::uint8_t, kPskSize>;

enum class RequestType : std::uint8_t { Subscribe = 1, Unsubscribe = 2 };
enum class ReplyType : std::uint8_t { Cookie = 0x81, Subscribed = 0x82, Unsubscribed = 0x83, Refused = 0x84 };

// Request flag bits (byte 5).
inline constexpr std::uint8_t kRequestAngularVelocity = 1u << 0;  // poses carry the body rate
inline constexpr std::uint8_t kRequestAuthenticated = 1u << 1;    // a 32-byte MAC ends the request
inline constexpr std::uint8_t kKnownRequestFlags = kRequestAngularVelocity | kRequestAuthenticated;

// Why a SUBSCRIBE was refused (REFUSED's byte 5). Sent only to an address that echoed a valid cookie.
enum class RefuseReason : std::uint8_t {
  None = 0,
  UnknownEncoding = 1,    // "unknown-encoding"
  UnknownStream = 2,      // "unknown-stream"
  TableFull = 3,          // "too-many-subscribers"
  AddressFull = 4,        // "too-many-for-address"
};
std::string_view to_string(RefuseReason r);

struct SubscriptionRequest {
  RequestType type = RequestType::Subscribe;
  bool angular_velocity = false;
  std::uint32_t request_id = 0;  // chosen by the client, echoed in the reply; renewals must increase it
  std::uint32_t lease_ms = 0;    // SUBSCRIBE: the lease asked for
  Cookie cookie{};               // all zeros: none
  std::string encoding;          // an output encoding's registry name (SUBSCRIBE)
  std::vector<std::uint32_t> streams;  // stream ids; empty = every stream
  bool has_cookie() const;
};

enum class RequestError : std::uint8_t {
  None = 0,
  TooShort,        // "too-short"
  Oversized,       // "oversized": beyond kMaxDatagramSize
  BadMagic,        // "bad-magic"
  BadType,         // "bad-type"
  UnknownFlags,    // "unknown-flags"
  BadLength,       // "bad-length": the size does not match the counts (and MAC)
  BadEncodingName, // "bad-encoding-name": empty for SUBSCRIBE, too long, or not [a-z0-9-]
  TooManyStreams,  // "too-many-streams"
};
inline constexpr std::size_t kRequestErrorCount = 9;
std::string_view to_string(RequestError e);

struct ParsedRequest {
  RequestError error = RequestError::None;
  SubscriptionRequest request;
  // With kRequestAuthenticated: the bytes the MAC covers and the MAC (empty spans otherwise).
  std::span<const std::uint8_t> signed_bytes;
  std::span<const std::uint8_t> mac;
  explicit operator bool() const { return error == RequestError::None; }
};

// Decodes a request. Does not check the MAC (see request_mac_valid) or the cookie.
ParsedRequest parse_request(std::span<const std::uint8_t> datagram);
// The request's bytes; with psk, flagged and followed by its MAC.
std::vector<std::uint8_t> encode_request(const SubscriptionRequest& r, const std::optional<PreSharedKey>& psk = {});
// True when the parsed request carries a MAC and it is the psk's MAC of its bytes (constant time).
bool request_mac_valid(const ParsedRequest& p, const PreSharedKey& psk);

struct SubscriptionReply {
  ReplyType type = ReplyType::Cookie;
  RefuseReason reason = RefuseReason::None;
  std::uint32_t request_id = 0;
  std::uint32_t lease_ms = 0;  // SUBSCRIBED: the lease granted
  Cookie cookie{};             // COOKIE: the cookie to echo
};

std::array<std::uint8_t, kReplySize> encode_reply(const SubscriptionReply& r);
// nullopt unless the datagram is a well-formed 32-byte reply.
std::optional<SubscriptionReply> parse_reply(std::span<const std::uint8_t> datagram);

// A key file: 32 bytes given as 64 hex digits (whitespace around them ignored). nullopt otherwise.
std::optional<PreSharedKey> parse_psk(std::string_view text);

}  // namespace posefair::daemon
