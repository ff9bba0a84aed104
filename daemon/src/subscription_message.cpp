#include "posefair/daemon/subscription_message.hpp"

#include <sodium.h>

#include <algorithm>
#include <cstring>

#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::daemon {
namespace {

// Request layout (docs/protocol.md, "Subscribing").
namespace off {
inline constexpr std::size_t kMagic = 0, kType = 4, kFlags = 5, kEncodingLength = 6, kStreamCount = 7, kRequestId = 8,
                             kLease = 12, kCookie = 16, kEncoding = 32;
}

std::uint32_t get_u32(std::span<const std::uint8_t> b, std::size_t at) {
  return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
         static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
}

void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

bool encoding_char(std::uint8_t c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'; }

}  // namespace

std::string_view to_string(RefuseReason r) {
  switch (r) {
    case RefuseReason::None: return "none";
    case RefuseReason::UnknownEncoding: return "unknown-encoding";
    case RefuseReason::UnknownStream: return "unknown-stream";
    case RefuseReason::TableFull: return "too-many-subscribers";
    case RefuseReason::AddressFull: return "too-many-for-address";
  }
  return "unknown";
}

std::string_view to_string(RequestError e) {
  switch (e) {
    case RequestError::None: return "ok";
    case RequestError::TooShort: return "too-short";
    case RequestError::Oversized: return "oversized";
    case RequestError::BadMagic: return "bad-magic";
    case RequestError::BadType: return "bad-type";
    case RequestError::UnknownFlags: return "unknown-flags";
    case RequestError::BadLength: return "bad-length";
    case RequestError::BadEncodingName: return "bad-encoding-name";
    case RequestError::TooManyStreams: return "too-many-streams";
  }
  return "unknown";
}

bool SubscriptionRequest::has_cookie() const {
  return std::any_of(cookie.begin(), cookie.end(), [](std::uint8_t b) { return b != 0; });
}

ParsedRequest parse_request(std::span<const std::uint8_t> d) {
  ParsedRequest p;
  auto fail = [&](RequestError e) {
    p.error = e;
    return p;
  };
  if (d.size() > kMaxDatagramSize) return fail(RequestError::Oversized);
  if (d.size() < kRequestHeaderSize) return fail(RequestError::TooShort);
  if (!std::equal(kSubscriptionMagic.begin(), kSubscriptionMagic.end(), d.begin())) return fail(RequestError::BadMagic);
  const std::uint8_t type = d[off::kType];
  if (type != static_cast<std::uint8_t>(RequestType::Subscribe) && type != static_cast<std::uint8_t>(RequestType::Unsubscribe))
    return fail(RequestError::BadType);
  const std::uint8_t flags = d[off::kFlags];
  if ((flags & ~kKnownRequestFlags) != 0) return fail(RequestError::UnknownFlags);
  const std::size_t encoding_length = d[off::kEncodingLength];
  const std::size_t streams = d[off::kStreamCount];
  if (streams > kMaxRequestStreams) return fail(RequestError::TooManyStreams);
  const std::size_t mac = (flags & kRequestAuthenticated) ? kRequestMacSize : 0;
  if (d.size() != kRequestHeaderSize + encoding_length + 4 * streams + mac) return fail(RequestError::BadLength);
  const bool subscribe = type == static_cast<std::uint8_t>(RequestType::Subscribe);
  if (encoding_length > kMaxEncodingName || (subscribe && encoding_length == 0)) return fail(RequestError::BadEncodingName);
  for (std::size_t i = 0; i < encoding_length; ++i)
    if (!encoding_char(d[off::kEncoding + i])) return fail(RequestError::BadEncodingName);

  SubscriptionRequest& r = p.request;
  r.type = static_cast<RequestType>(type);
  r.angular_velocity = (flags & kRequestAngularVelocity) != 0;
  r.request_id = get_u32(d, off::kRequestId);
  r.lease_ms = get_u32(d, off::kLease);
  std::copy_n(d.begin() + off::kCookie, kCookieSize, r.cookie.begin());
  r.encoding.assign(reinterpret_cast<const char*>(d.data() + off::kEncoding), encoding_length);
  const std::size_t ids = off::kEncoding + encoding_length;
  for (std::size_t i = 0; i < streams; ++i) r.streams.push_back(get_u32(d, ids + 4 * i));
  if (mac != 0) {
    p.signed_bytes = d.first(d.size() - mac);
    p.mac = d.last(mac);
  }
  return p;
}

std::vector<std::uint8_t> encode_request(const SubscriptionRequest& r, const std::optional<PreSharedKey>& psk) {
  const std::size_t encoding = std::min(r.encoding.size(), kMaxEncodingName);
  const std::size_t streams = std::min(r.streams.size(), kMaxRequestStreams);
  std::vector<std::uint8_t> b(kRequestHeaderSize + encoding + 4 * streams, 0);
  std::copy(kSubscriptionMagic.begin(), kSubscriptionMagic.end(), b.begin());
  b[off::kType] = static_cast<std::uint8_t>(r.type);
  b[off::kFlags] = static_cast<std::uint8_t>((r.angular_velocity ? kRequestAngularVelocity : 0) | (psk ? kRequestAuthenticated : 0));
  b[off::kEncodingLength] = static_cast<std::uint8_t>(encoding);
  b[off::kStreamCount] = static_cast<std::uint8_t>(streams);
  put_u32(&b[off::kRequestId], r.request_id);
  put_u32(&b[off::kLease], r.lease_ms);
  std::copy(r.cookie.begin(), r.cookie.end(), b.begin() + off::kCookie);
  std::memcpy(&b[off::kEncoding], r.encoding.data(), encoding);
  for (std::size_t i = 0; i < streams; ++i) put_u32(&b[off::kEncoding + encoding + 4 * i], r.streams[i]);
  if (psk) {
    std::array<std::uint8_t, kRequestMacSize> mac{};
    ::crypto_auth(mac.data(), b.data(), b.size(), psk->data());
    b.insert(b.end(), mac.begin(), mac.end());
  }
  return b;
}

bool request_mac_valid(const ParsedRequest& p, const PreSharedKey& psk) {
  if (!p || p.mac.size() != kRequestMacSize) return false;
  return ::crypto_auth_verify(p.mac.data(), p.signed_bytes.data(), p.signed_bytes.size(), psk.data()) == 0;
}

std::array<std::uint8_t, kReplySize> encode_reply(const SubscriptionReply& r) {
  std::array<std::uint8_t, kReplySize> b{};
  std::copy(kSubscriptionMagic.begin(), kSubscriptionMagic.end(), b.begin());
  b[4] = static_cast<std::uint8_t>(r.type);
  b[5] = static_cast<std::uint8_t>(r.reason);
  put_u32(&b[8], r.request_id);
  put_u32(&b[12], r.lease_ms);
  std::copy(r.cookie.begin(), r.cookie.end(), b.begin() + 16);
  return b;
}

std::optional<SubscriptionReply> parse_reply(std::span<const std::uint8_t> d) {
  if (d.size() != kReplySize || !std::equal(kSubscriptionMagic.begin(), kSubscriptionMagic.end(), d.begin())) return std::nullopt;
  SubscriptionReply r;
  const std::uint8_t type = d[4];
  if (type < static_cast<std::uint8_t>(ReplyType::Cookie) || type > static_cast<std::uint8_t>(ReplyType::Refused)) return std::nullopt;
  if (d[5] > static_cast<std::uint8_t>(RefuseReason::AddressFull) || d[6] != 0 || d[7] != 0) return std::nullopt;
  r.type = static_cast<ReplyType>(type);
  r.reason = static_cast<RefuseReason>(d[5]);
  r.request_id = get_u32(d, 8);
  r.lease_ms = get_u32(d, 12);
  std::copy_n(d.begin() + 16, kCookieSize, r.cookie.begin());
  return r;
}

std::optional<PreSharedKey> parse_psk(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return std::nullopt;
  text = text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
  PreSharedKey key{};
  std::size_t got = 0;
  if (text.size() != 2 * kPskSize ||
      ::sodium_hex2bin(key.data(), key.size(), text.data(), text.size(), nullptr, &got, nullptr) != 0 || got != kPskSize)
    return std::nullopt;
  return key;
}

}  // namespace posefair::daemon
