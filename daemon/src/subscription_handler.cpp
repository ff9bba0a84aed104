#include "posefair/daemon/subscription_handler.hpp"

#include <algorithm>

namespace posefair::daemon {
namespace {
constexpr auto relaxed = std::memory_order_relaxed;
}

SubscriptionHandler::SubscriptionHandler(SubscriptionSettings settings, std::shared_ptr<SubscriberTable> table)
    : settings_(std::move(settings)),
      table_(std::move(table)),
      cookies_(settings_.cookie_slot),
      limiter_(settings_.source_table, settings_.rate_per_source, settings_.burst_per_source) {}

void SubscriptionHandler::set_streams(std::vector<std::uint32_t> ids) {
  std::lock_guard lock(streams_mutex_);
  streams_ = std::move(ids);
}

std::size_t SubscriptionHandler::expire(std::chrono::nanoseconds now) {
  const std::size_t n = table_->expire(now.count());
  counters_.expired.fetch_add(n, relaxed);
  return n;
}

std::optional<std::array<std::uint8_t, kReplySize>> SubscriptionHandler::handle(std::span<const std::uint8_t> datagram,
                                                                                const Endpoint& source,
                                                                                std::chrono::nanoseconds now) {
  counters_.datagrams.fetch_add(1, relaxed);
  counters_.bytes_in.fetch_add(datagram.size(), relaxed);
  if (!settings_.allow.allows(source)) {
    counters_.not_allowed.fetch_add(1, relaxed);
    return std::nullopt;
  }
  if (!limiter_.allow(source, now)) {
    counters_.rate_limited.fetch_add(1, relaxed);
    return std::nullopt;
  }
  const ParsedRequest parsed = parse_request(datagram);
  if (!parsed) {
    counters_.malformed.fetch_add(1, relaxed);
    return std::nullopt;
  }
  if (settings_.psk && !request_mac_valid(parsed, *settings_.psk)) {
    counters_.unauthenticated.fetch_add(1, relaxed);
    return std::nullopt;
  }
  const SubscriptionRequest& r = parsed.request;
  std::optional<std::array<std::uint8_t, kReplySize>> reply;
  if (!r.has_cookie() || !cookies_.valid(source, r.cookie, now)) {
    if (r.has_cookie()) counters_.bad_cookie.fetch_add(1, relaxed);
    counters_.unverified_bytes_in.fetch_add(datagram.size(), relaxed);
    SubscriptionReply c;
    c.type = ReplyType::Cookie;
    c.request_id = r.request_id;
    c.cookie = cookies_.make(source, now);
    reply = encode_reply(c);
    // Never more bytes out than in before the address is verified (requests are >= 32 bytes).
    if (reply->size() > datagram.size()) return std::nullopt;
    counters_.cookies_sent.fetch_add(1, relaxed);
    counters_.unverified_bytes_out.fetch_add(reply->size(), relaxed);
  } else if (r.type == RequestType::Unsubscribe) {
    SubscriptionReply u;
    u.type = ReplyType::Unsubscribed;
    u.request_id = r.request_id;
    if (table_->unsubscribe(source, r.request_id)) counters_.unsubscribed.fetch_add(1, relaxed);
    reply = encode_reply(u);
  } else {
    reply = subscribe(r, source, now);
  }
  if (reply) counters_.bytes_out.fetch_add(reply->size(), relaxed);
  return reply;
}

std::optional<std::array<std::uint8_t, kReplySize>> SubscriptionHandler::subscribe(const SubscriptionRequest& r,
                                                                                   const Endpoint& source,
                                                                                   std::chrono::nanoseconds now) {
  SubscriptionReply reply;
  reply.request_id = r.request_id;
  auto refuse = [&](RefuseReason why) {
    counters_.refused.fetch_add(1, relaxed);
    reply.type = ReplyType::Refused;
    reply.reason = why;
    return encode_reply(reply);
  };
  const auto entries = output_encoder_entries();
  const auto encoding = std::find_if(entries.begin(), entries.end(), [&](const OutputEncoderEntry* e) { return e->name == r.encoding; });
  if (encoding == entries.end() || !offered_to_subscribers(**encoding)) return refuse(RefuseReason::UnknownEncoding);
  {
    std::lock_guard lock(streams_mutex_);
    for (std::uint32_t id : r.streams)
      if (std::find(streams_.begin(), streams_.end(), id) == streams_.end()) return refuse(RefuseReason::UnknownStream);
  }
  Subscriber s;
  s.address = source;
  s.encoding = static_cast<std::uint8_t>(encoding - entries.begin());
  s.angular_velocity = r.angular_velocity;
  s.stream_count = static_cast<std::uint8_t>(r.streams.size());
  std::copy(r.streams.begin(), r.streams.end(), s.streams.begin());
  const double lease = std::clamp(static_cast<double>(r.lease_ms) / 1000.0, settings_.min_lease, settings_.max_lease);
  s.since_ns = now.count();
  s.expires_ns = now.count() + static_cast<std::int64_t>(lease * 1e9);
  s.last_request_id = r.request_id;
  switch (table_->subscribe(s)) {
    case SubscriberTable::Outcome::Added: counters_.subscribed.fetch_add(1, relaxed); break;
    case SubscriberTable::Outcome::Renewed: counters_.renewed.fetch_add(1, relaxed); break;
    case SubscriberTable::Outcome::Replayed: counters_.replayed.fetch_add(1, relaxed); return std::nullopt;
    case SubscriberTable::Outcome::TableFull: return refuse(RefuseReason::TableFull);
    case SubscriberTable::Outcome::AddressFull: return refuse(RefuseReason::AddressFull);
  }
  reply.type = ReplyType::Subscribed;
  reply.lease_ms = static_cast<std::uint32_t>(lease * 1000.0);
  return encode_reply(reply);
}

}  // namespace posefair::daemon
