#include "posefair/daemon/subscription_client.hpp"

namespace posefair::daemon {

SubscriptionClient::SubscriptionClient(Endpoint server, SubscriptionRequest request, std::optional<PreSharedKey> psk,
                                       std::uint32_t first_request_id)
    : server_(server), request_(std::move(request)), psk_(psk), next_id_(first_request_id) {}

std::uint32_t SubscriptionClient::first_request_id_now() {
  constexpr std::int64_t k2025 = 1735689600;  // 2025-01-01T00:00:00Z
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  const std::int64_t tenths = std::chrono::duration_cast<std::chrono::milliseconds>(now).count() / 100 - k2025 * 10;
  return static_cast<std::uint32_t>(std::max<std::int64_t>(tenths, 1));
}

std::vector<std::uint8_t> SubscriptionClient::request(RequestType type, bool with_cookie) {
  SubscriptionRequest r = request_;
  r.type = type;
  r.request_id = awaiting_id_ = next_id_++;
  r.cookie = with_cookie ? cookie_ : Cookie{};
  if (type == RequestType::Unsubscribe) {
    r.encoding.clear();
    r.streams.clear();
    r.lease_ms = 0;
  }
  return encode_request(r, psk_);
}

std::optional<std::vector<std::uint8_t>> SubscriptionClient::due(Clock::time_point now) {
  switch (state_) {
    case State::Refused:
    case State::Failed:
      return std::nullopt;
    case State::Subscribed:
      if (now < next_send_) return std::nullopt;
      state_ = State::Starting;  // renew: a fresh cookie first
      tries_ = 0;
      [[fallthrough]];
    case State::Starting:
      state_ = State::AwaitingCookie;
      next_send_ = now + kRetry;
      ++tries_;
      return request(RequestType::Subscribe, false);
    case State::AwaitingCookie:
    case State::AwaitingSubscribed:
      if (now < next_send_) return std::nullopt;
      // No answer: lost, or rate limited. Give up only before the first subscription; a
      // renewal keeps trying while the lease lasts.
      if (tries_ >= kMaxTries && (!subscribed_once_ || now >= lease_end_)) {
        state_ = State::Failed;
        return std::nullopt;
      }
      ++tries_;
      next_send_ = now + kRetry;
      return request(RequestType::Subscribe, state_ == State::AwaitingSubscribed);
  }
  return std::nullopt;
}

bool SubscriptionClient::on_reply(std::span<const std::uint8_t> datagram, const Endpoint& from, Clock::time_point now) {
  if (!(from == server_)) return false;
  const auto reply = parse_reply(datagram);
  if (!reply) return false;
  if (reply->request_id != awaiting_id_) return true;  // an answer to an earlier try
  switch (reply->type) {
    case ReplyType::Cookie:
      cookie_ = reply->cookie;
      if (state_ == State::AwaitingCookie || state_ == State::AwaitingSubscribed) {
        state_ = State::AwaitingSubscribed;
        next_send_ = now;  // send the SUBSCRIBE with the cookie at once
      }
      break;
    case ReplyType::Subscribed:
      state_ = State::Subscribed;
      subscribed_once_ = true;
      granted_ms_ = reply->lease_ms;
      lease_end_ = now + std::chrono::milliseconds(reply->lease_ms);
      next_send_ = now + std::chrono::milliseconds(reply->lease_ms / 3);
      tries_ = 0;
      break;
    case ReplyType::Refused:
      state_ = State::Refused;
      refused_ = reply->reason;
      break;
    case ReplyType::Unsubscribed:
      break;
  }
  return true;
}

std::vector<std::uint8_t> SubscriptionClient::unsubscribe() { return request(RequestType::Unsubscribe, true); }

}  // namespace posefair::daemon
