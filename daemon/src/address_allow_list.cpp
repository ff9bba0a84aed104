#include "posefair/daemon/address_allow_list.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <charconv>
#include <cstring>

namespace posefair::daemon {

std::size_t AddressBytes::size() const { return family == AF_INET ? 4 : 16; }

AddressBytes address_bytes(const Endpoint& e) {
  AddressBytes a;
  if (e.family() == AF_INET) {
    const auto* sin = reinterpret_cast<const sockaddr_in*>(e.sockaddr_ptr());
    a.family = AF_INET;
    std::memcpy(a.bytes.data(), &sin->sin_addr, 4);
  } else if (e.family() == AF_INET6) {
    const auto* sin6 = reinterpret_cast<const sockaddr_in6*>(e.sockaddr_ptr());
    if (IN6_IS_ADDR_V4MAPPED(&sin6->sin6_addr)) {
      a.family = AF_INET;
      std::memcpy(a.bytes.data(), reinterpret_cast<const std::uint8_t*>(&sin6->sin6_addr) + 12, 4);
    } else {
      a.family = AF_INET6;
      std::memcpy(a.bytes.data(), &sin6->sin6_addr, 16);
    }
  }
  return a;
}

std::optional<CidrRange> CidrRange::parse(std::string_view text) {
  const std::size_t slash = text.find('/');
  const auto address = Endpoint::parse_address(text.substr(0, slash));
  if (!address) return std::nullopt;
  CidrRange r;
  r.network = address_bytes(*address);
  const int bits = static_cast<int>(8 * r.network.size());
  r.prefix = bits;
  if (slash != std::string_view::npos) {
    const std::string_view p = text.substr(slash + 1);
    int v = -1;
    const auto [end, ec] = std::from_chars(p.data(), p.data() + p.size(), v);
    if (ec != std::errc{} || end != p.data() + p.size() || p.empty() || v < 0 || v > bits) return std::nullopt;
    r.prefix = v;
  }
  // Keep only the network part, so "10.1.2.3/8" means 10.0.0.0/8.
  for (int i = 0; i < bits; ++i)
    if (i >= r.prefix) r.network.bytes[static_cast<std::size_t>(i / 8)] &= static_cast<std::uint8_t>(~(0x80u >> (i % 8)));
  return r;
}

bool CidrRange::contains(const AddressBytes& a) const {
  if (a.family != network.family) return false;
  for (int i = 0; i < prefix; ++i) {
    const auto byte = static_cast<std::size_t>(i / 8);
    const auto mask = static_cast<std::uint8_t>(0x80u >> (i % 8));
    if ((a.bytes[byte] & mask) != (network.bytes[byte] & mask)) return false;
  }
  return true;
}

std::string CidrRange::to_string() const {
  char buf[INET6_ADDRSTRLEN] = {};
  ::inet_ntop(network.family, network.bytes.data(), buf, sizeof buf);
  return std::string(buf) + "/" + std::to_string(prefix);
}

AddressAllowList AddressAllowList::loopback() {
  return AddressAllowList({*CidrRange::parse("127.0.0.0/8"), *CidrRange::parse("::1/128")});
}

bool AddressAllowList::allows(const Endpoint& source) const {
  const AddressBytes a = address_bytes(source);
  return std::any_of(ranges_.begin(), ranges_.end(), [&](const CidrRange& r) { return r.contains(a); });
}

}  // namespace posefair::daemon
