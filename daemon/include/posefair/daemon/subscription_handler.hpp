#pragma once
// What the subscription port does with one datagram (docs/protocol.md, "Subscribing";
// docs/security.md): pure policy, no socket and no clock, so tests and the flood benchmark
// drive it directly. In order, each step dropping the datagram silently and counting it:
//   1. the source must be in the allow list;
//   2. the source's token bucket must have a token (rate per source);
//   3. the request must parse;
//   4. with a pre-shared key, its MAC must verify;
//   5. without a valid cookie for the source address and port, the only answer is a COOKIE,
//      no larger than the request (so a reflected flood is no bigger than the flood, and a
//      spoofed victim gets at most its address's rate of them);
//   6. with one, the subscriber table acts (add, renew, remove) and the answer is SUBSCRIBED,
//      UNSUBSCRIBED or REFUSED.
// Nothing but a COOKIE is ever sent to an address that has not echoed a cookie.
#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "posefair/daemon/address_allow_list.hpp"
#include "posefair/daemon/source_rate_limiter.hpp"
#include "posefair/daemon/subscriber_table.hpp"
#include "posefair/daemon/subscription_cookie.hpp"
#include "posefair/daemon/subscription_message.hpp"

namespace posefair::daemon {

// [subscription] (docs/config.md).
struct SubscriptionSettings {
  Endpoint listen = *Endpoint::parse("127.0.0.1:5710");
  AddressAllowList allow = AddressAllowList::loopback();
  std::uint32_t max_subscribers = 16;
  std::uint32_t max_per_address = 4;
  double rate_per_source = 20.0;    // control datagrams a second from one address
  double burst_per_source = 10.0;
  std::uint32_t source_table = 4096;  // token buckets kept (memory bound)
  double max_lease = 60.0;          // s
  double min_lease = 1.0;           // s
  std::chrono::seconds cookie_slot{10};
  std::optional<PreSharedKey> psk;  // psk_file: SUBSCRIBE and UNSUBSCRIBE must carry its MAC
};

struct SubscriptionCounters {
  std::atomic<std::uint64_t> datagrams{0}, bytes_in{0}, bytes_out{0}, not_allowed{0}, rate_limited{0}, malformed{0},
      unauthenticated{0}, cookies_sent{0}, bad_cookie{0}, subscribed{0}, renewed{0},
      replayed{0}, unsubscribed{0}, refused{0}, expired{0};
  // Bytes of requests that carried no valid cookie, and of the replies they got: the
  // amplification factor is unverified_bytes_out / unverified_bytes_in.
  std::atomic<std::uint64_t> unverified_bytes_in{0}, unverified_bytes_out{0};
};

class SubscriptionHandler {
 public:
  SubscriptionHandler(SubscriptionSettings settings, std::shared_ptr<SubscriberTable> table);
  // The stream ids a SUBSCRIBE may name (set at start and at every reload).
  void set_streams(std::vector<std::uint32_t> ids);
  // The reply to send back to `source`, if any. `now`: steady clock.
  std::optional<std::array<std::uint8_t, kReplySize>> handle(std::span<const std::uint8_t> datagram, const Endpoint& source,
                                                             std::chrono::nanoseconds now);
  // Ends the leases that ran out; returns how many.
  std::size_t expire(std::chrono::nanoseconds now);

  const SubscriptionCounters& counters() const { return counters_; }
  const SubscriptionSettings& settings() const { return settings_; }
  SubscriberTable& table() { return *table_; }

 private:
  std::optional<std::array<std::uint8_t, kReplySize>> subscribe(const SubscriptionRequest& r, const Endpoint& source,
                                                                std::chrono::nanoseconds now);
  SubscriptionSettings settings_;
  std::shared_ptr<SubscriberTable> table_;
  CookieJar cookies_;
  SourceRateLimiter limiter_;
  std::mutex streams_mutex_;
  std::vector<std::uint32_t> streams_;
  SubscriptionCounters counters_;
};

}  // namespace posefair::daemon
