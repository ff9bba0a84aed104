#pragma once
// Stateless cookies for the subscription handshake, as DTLS's HelloVerifyRequest and QUIC's
// Retry: the cookie is a keyed MAC (libsodium crypto_generichash, BLAKE2b, keyed) of the
// client's address, port and a coarse time slot, under a key drawn at start. The daemon keeps
// nothing per unverified client; a client that echoes a cookie the daemon can recompute has
// shown that it receives at the address it claims. A cookie is valid in its slot and the next
// (between one and two slot lengths), and for no other address or port.
#include <array>
#include <chrono>
#include <cstdint>

#include "posefair/daemon/subscription_message.hpp"
#include "posefair/daemon/udp_socket.hpp"

namespace posefair::daemon {

class CookieJar {
 public:
  // A fresh random key (libsodium randombytes). slot: the coarse time step.
  explicit CookieJar(std::chrono::seconds slot = std::chrono::seconds(10));
  // `now` is any monotonic clock's reading (the daemon's steady clock; tests choose it).
  Cookie make(const Endpoint& client, std::chrono::nanoseconds now) const;
  // Constant-time comparison against this slot's and the previous slot's cookie.
  bool valid(const Endpoint& client, const Cookie& cookie, std::chrono::nanoseconds now) const;
  std::chrono::seconds slot() const { return slot_; }

 private:
  Cookie make_for_slot(const Endpoint& client, std::uint64_t slot) const;
  std::array<std::uint8_t, 32> key_{};
  std::chrono::seconds slot_;
};

}  // namespace posefair::daemon
