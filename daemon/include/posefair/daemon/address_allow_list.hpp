#pragma once
// Which source addresses may talk to the subscription port: a list of CIDR ranges
// ("127.0.0.0/8", "::1/128", "192.168.10.0/24"), as chrony's allow directive. An IPv4-mapped
// IPv6 source (::ffff:a.b.c.d, from a dual-stack socket) is judged as the IPv4 address it is.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/daemon/udp_socket.hpp"

namespace posefair::daemon {

// An address as bytes: 4 for IPv4 (mapped addresses unwrapped), 16 for IPv6.
struct AddressBytes {
  int family = 0;  // AF_INET or AF_INET6
  std::array<std::uint8_t, 16> bytes{};
  std::size_t size() const;
};
AddressBytes address_bytes(const Endpoint& e);

struct CidrRange {
  AddressBytes network;
  int prefix = 0;  // bits
  // "ADDR/BITS", or an address alone (a single host). nullopt if malformed or the prefix is
  // longer than the address.
  static std::optional<CidrRange> parse(std::string_view text);
  bool contains(const AddressBytes& a) const;
  std::string to_string() const;
};

class AddressAllowList {
 public:
  AddressAllowList() = default;
  explicit AddressAllowList(std::vector<CidrRange> ranges) : ranges_(std::move(ranges)) {}
  // 127.0.0.0/8 and ::1/128: this host only.
  static AddressAllowList loopback();
  bool allows(const Endpoint& source) const;
  const std::vector<CidrRange>& ranges() const { return ranges_; }

 private:
  std::vector<CidrRange> ranges_;
};

}  // namespace posefair::daemon
