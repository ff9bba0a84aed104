#include "posefair/daemon/subscription_cookie.hpp"

#include <sodium.h>

#include <stdexcept>

#include "posefair/daemon/address_allow_list.hpp"

namespace posefair::daemon {

CookieJar::CookieJar(std::chrono::seconds slot) : slot_(slot) {
  if (::sodium_init() < 0) throw std::runtime_error("libsodium could not be initialised");
  if (slot_.count() <= 0) throw std::invalid_argument("cookie slot must be positive");
  ::randombytes_buf(key_.data(), key_.size());
}

Cookie CookieJar::make_for_slot(const Endpoint& client, std::uint64_t slot) const {
  // family, address (4 or 16 bytes), port, slot: fixed positions, so no two inputs collide.
  const AddressBytes a = address_bytes(client);
  std::array<std::uint8_t, 1 + 16 + 2 + 8> in{};
  in[0] = static_cast<std::uint8_t>(a.family == AF_INET ? 4 : 6);
  std::copy(a.bytes.begin(), a.bytes.end(), in.begin() + 1);
  in[17] = static_cast<std::uint8_t>(client.port() >> 8);
  in[18] = static_cast<std::uint8_t>(client.port());
  for (int i = 0; i < 8; ++i) in[static_cast<std::size_t>(19 + i)] = static_cast<std::uint8_t>(slot >> (8 * i));
  Cookie c{};
  ::crypto_generichash(c.data(), c.size(), in.data(), in.size(), key_.data(), key_.size());
  return c;
}

Cookie CookieJar::make(const Endpoint& client, std::chrono::nanoseconds now) const {
  return make_for_slot(client, static_cast<std::uint64_t>(now / slot_));
}

bool CookieJar::valid(const Endpoint& client, const Cookie& cookie, std::chrono::nanoseconds now) const {
  const auto slot = static_cast<std::uint64_t>(now / slot_);
  const Cookie current = make_for_slot(client, slot);
  bool ok = ::crypto_verify_16(current.data(), cookie.data()) == 0;
  if (slot > 0) {
    const Cookie previous = make_for_slot(client, slot - 1);
    ok = (::crypto_verify_16(previous.data(), cookie.data()) == 0) || ok;
  }
  return ok;
}

}  // namespace posefair::daemon
