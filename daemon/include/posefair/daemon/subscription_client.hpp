#pragma once
// The client's side of the subscription handshake (docs/protocol.md, "Subscribing"), as a state
// machine without a socket or a clock of its own, so a receive loop that also reads poses can
// drive it: due() says what to send now (the first SUBSCRIBE, a retry, a renewal at a third of
// the lease), on_reply() takes the daemon's replies. Used by `posefair sub --subscribe`;
// tools/posefair_sub.py does the same in Python.
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "posefair/daemon/subscription_message.hpp"
#include "posefair/daemon/udp_socket.hpp"

namespace posefair::daemon {

class SubscriptionClient {
 public:
  using Clock = std::chrono::steady_clock;
  enum class State { Starting, AwaitingCookie, AwaitingSubscribed, Subscribed, Refused, Failed };

  // `request`: encoding, streams, lease and angular velocity wanted (type, cookie and request id
  // are the client's). `first_request_id`: above any id this address and port used before
  // (first_request_id_now() derives one from the wall clock).
  SubscriptionClient(Endpoint server, SubscriptionRequest request, std::optional<PreSharedKey> psk,
                     std::uint32_t first_request_id);

  // A request to send to server() now, if one is due.
  std::optional<std::vector<std::uint8_t>> due(Clock::time_point now);
  // A datagram from `from`: true when it was the server's reply (consumed), false for anything else.
  bool on_reply(std::span<const std::uint8_t> datagram, const Endpoint& from, Clock::time_point now);
  // An UNSUBSCRIBE with the last cookie (the daemon answers COOKIE if it has gone stale; then
  // call it again).
  std::vector<std::uint8_t> unsubscribe();

  State state() const { return state_; }
  bool subscribed_once() const { return subscribed_once_; }
  RefuseReason refused_because() const { return refused_; }
  std::uint32_t lease_ms() const { return granted_ms_; }
  const Endpoint& server() const { return server_; }
  // Tenths of a second since 2025-01-01 UTC: a client restarted on the same port starts above
  // the ids it used before (the daemon refuses a renewal whose id does not increase).
  static std::uint32_t first_request_id_now();

  static constexpr std::chrono::milliseconds kRetry{300};
  static constexpr int kMaxTries = 10;

 private:
  std::vector<std::uint8_t> request(RequestType type, bool with_cookie);
  Endpoint server_;
  SubscriptionRequest request_;
  std::optional<PreSharedKey> psk_;
  std::uint32_t next_id_;
  std::uint32_t awaiting_id_ = 0;
  State state_ = State::Starting;
  Cookie cookie_{};
  Clock::time_point next_send_{};
  Clock::time_point lease_end_{};
  int tries_ = 0;
  bool subscribed_once_ = false;
  std::uint32_t granted_ms_ = 0;
  RefuseReason refused_ = RefuseReason::None;
};

}  // namespace posefair::daemon
