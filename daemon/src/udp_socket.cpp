#include "posefair/daemon/udp_socket.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <limits>
#include <system_error>
#include <utility>

namespace posefair::daemon {
namespace {

[[noreturn]] void throw_errno(int err, const std::string& what) {
  throw std::system_error(err, std::generic_category(), what);
}

std::optional<std::uint16_t> parse_port(std::string_view s) {
  if (s.empty() || s.size() > 5) return std::nullopt;
  unsigned value = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), value);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || value > 65535) return std::nullopt;
  return static_cast<std::uint16_t>(value);
}

bool parse_ipv4(std::string_view s, in_addr& out) {
  if (s.empty() || s.size() >= INET_ADDRSTRLEN) return false;
  const std::string z(s);
  return inet_pton(AF_INET, z.c_str(), &out) == 1;  // strict dotted quad, unlike inet_aton
}

// Numeric IPv6, with an optional "%zone" (interface name or index), via getaddrinfo.
bool parse_ipv6(std::string_view s, sockaddr_in6& out) {
  if (s.empty() || s.size() > 100 || s.find(':') == std::string_view::npos) return false;
  const std::string z(s);
  addrinfo hints{};
  hints.ai_family = AF_INET6;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICHOST;
  addrinfo* res = nullptr;
  if (getaddrinfo(z.c_str(), nullptr, &hints, &res) != 0 || res == nullptr) return false;
  std::memcpy(&out, res->ai_addr, sizeof out);
  freeaddrinfo(res);
  return true;
}

int set_nonblocking_cloexec(int fd) {
  const int fl = fcntl(fd, F_GETFL, 0);
  if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) < 0) return -1;
  const int fd_flags = fcntl(fd, F_GETFD, 0);
  if (fd_flags < 0 || fcntl(fd, F_SETFD, fd_flags | FD_CLOEXEC) < 0) return -1;
  return 0;
}

template <typename T>
void set_option(int fd, int level, int name, const T& value, const std::string& what) {
  if (setsockopt(fd, level, name, &value, sizeof value) != 0) throw_errno(errno, what);
}

// The index of an interface given by name, by number, or by one of its addresses; 0 if empty.
unsigned interface_index(const MulticastInterface& i) {
  const std::string& s = i.name_or_address;
  if (s.empty()) return 0;
  if (const unsigned idx = if_nametoindex(s.c_str()); idx != 0) return idx;
  unsigned number = 0;
  if (const auto r = std::from_chars(s.data(), s.data() + s.size(), number);
      r.ec == std::errc() && r.ptr == s.data() + s.size() && number > 0)
    return number;
  in_addr a4{};
  sockaddr_in6 a6{};
  const bool is4 = parse_ipv4(s, a4);
  const bool is6 = !is4 && parse_ipv6(s, a6);
  if (!is4 && !is6) throw_errno(ENODEV, "no network interface '" + s + "'");
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) throw_errno(errno, "getifaddrs");
  unsigned found = 0;
  for (const ifaddrs* p = list; p != nullptr && found == 0; p = p->ifa_next) {
    if (p->ifa_addr == nullptr) continue;
    if (is4 && p->ifa_addr->sa_family == AF_INET &&
        reinterpret_cast<const sockaddr_in*>(p->ifa_addr)->sin_addr.s_addr == a4.s_addr)
      found = if_nametoindex(p->ifa_name);
    if (is6 && p->ifa_addr->sa_family == AF_INET6 &&
        std::memcmp(&reinterpret_cast<const sockaddr_in6*>(p->ifa_addr)->sin6_addr, &a6.sin6_addr,
                    sizeof(in6_addr)) == 0)
      found = if_nametoindex(p->ifa_name);
  }
  freeifaddrs(list);
  if (found == 0) throw_errno(EADDRNOTAVAIL, "no network interface has the address " + s);
  return found;
}

// IPv4 interfaces are given to the kernel by address when they are one, else by index.
ip_mreqn ipv4_interface(const MulticastInterface& i) {
  ip_mreqn m{};
  m.imr_address.s_addr = htonl(INADDR_ANY);
  if (i.name_or_address.empty()) return m;
  if (parse_ipv4(i.name_or_address, m.imr_address)) return m;
  m.imr_ifindex = static_cast<int>(interface_index(i));
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Endpoint

std::optional<Endpoint> Endpoint::parse(std::string_view text, std::optional<std::uint16_t> default_port) {
  std::string_view host = text;
  std::optional<std::uint16_t> port = default_port;
  bool bracketed = false;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos) return std::nullopt;
    host = text.substr(1, close - 1);
    bracketed = true;
    const std::string_view rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return std::nullopt;
      port = parse_port(rest.substr(1));
      if (!port) return std::nullopt;
    }
  } else if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
    if (text.find(':') == colon) {  // exactly one colon: IPv4:port
      host = text.substr(0, colon);
      port = parse_port(text.substr(colon + 1));
      if (!port) return std::nullopt;
    }  // several colons and no brackets: a bare IPv6 address
  }
  if (!port) return std::nullopt;
  Endpoint e;
  in_addr a4{};
  sockaddr_in6 a6{};
  if (!bracketed && parse_ipv4(host, a4)) {
    auto* s = reinterpret_cast<sockaddr_in*>(&e.storage_);
    s->sin_family = AF_INET;
    s->sin_addr = a4;
    s->sin_port = htons(*port);
    e.len_ = sizeof(sockaddr_in);
    return e;
  }
  if (parse_ipv6(host, a6)) {
    a6.sin6_port = htons(*port);
    std::memcpy(&e.storage_, &a6, sizeof a6);
    e.len_ = sizeof(sockaddr_in6);
    return e;
  }
  return std::nullopt;
}

std::optional<Endpoint> Endpoint::parse_address(std::string_view text) {
  if (!text.empty() && text.front() == '[') return std::nullopt;
  if (text.find(':') != std::string_view::npos) {
    std::string bracketed(1, '[');  // (built up piecewise: GCC 12 warns falsely on "[" + string)
    bracketed.append(text);
    bracketed += ']';
    return parse(bracketed, 0);
  }
  return parse(text, 0);
}

Endpoint Endpoint::from_sockaddr(const sockaddr* sa, socklen_t len) {
  Endpoint e;
  len = std::min<socklen_t>(len, sizeof e.storage_);
  std::memcpy(&e.storage_, sa, len);
  e.len_ = len;
  return e;
}

std::uint16_t Endpoint::port() const {
  if (family() == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in*>(&storage_)->sin_port);
  if (family() == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&storage_)->sin6_port);
  return 0;
}

void Endpoint::set_port(std::uint16_t port) {
  if (family() == AF_INET) reinterpret_cast<sockaddr_in*>(&storage_)->sin_port = htons(port);
  if (family() == AF_INET6) reinterpret_cast<sockaddr_in6*>(&storage_)->sin6_port = htons(port);
}

bool Endpoint::is_multicast() const {
  if (family() == AF_INET) return IN_MULTICAST(ntohl(reinterpret_cast<const sockaddr_in*>(&storage_)->sin_addr.s_addr));
  if (family() == AF_INET6) return IN6_IS_ADDR_MULTICAST(&reinterpret_cast<const sockaddr_in6*>(&storage_)->sin6_addr);
  return false;
}

bool Endpoint::is_unspecified() const {
  if (family() == AF_INET) return reinterpret_cast<const sockaddr_in*>(&storage_)->sin_addr.s_addr == htonl(INADDR_ANY);
  if (family() == AF_INET6)
    return IN6_IS_ADDR_UNSPECIFIED(&reinterpret_cast<const sockaddr_in6*>(&storage_)->sin6_addr);
  return false;
}

std::string Endpoint::address_string() const {
  char buf[INET6_ADDRSTRLEN + IF_NAMESIZE + 2] = {};
  if (family() == AF_INET) {
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(&storage_)->sin_addr, buf, sizeof buf);
    return buf;
  }
  if (family() == AF_INET6) {
    const auto* s = reinterpret_cast<const sockaddr_in6*>(&storage_);
    inet_ntop(AF_INET6, &s->sin6_addr, buf, sizeof buf);
    std::string out = buf;
    if (s->sin6_scope_id != 0) {
      char name[IF_NAMESIZE] = {};
      out += '%';
      out += if_indextoname(s->sin6_scope_id, name) ? std::string(name) : std::to_string(s->sin6_scope_id);
    }
    return out;
  }
  return "(none)";
}

std::string Endpoint::to_string() const {
  std::string out;
  if (family() == AF_INET6) out += '[';
  out += address_string();
  if (family() == AF_INET6) out += ']';
  out += ':';
  out += std::to_string(port());
  return out;
}

bool operator==(const Endpoint& a, const Endpoint& b) {
  if (a.family() != b.family()) return false;
  if (a.family() == AF_INET) {
    const auto* x = reinterpret_cast<const sockaddr_in*>(&a.storage_);
    const auto* y = reinterpret_cast<const sockaddr_in*>(&b.storage_);
    return x->sin_addr.s_addr == y->sin_addr.s_addr && x->sin_port == y->sin_port;
  }
  if (a.family() == AF_INET6) {
    const auto* x = reinterpret_cast<const sockaddr_in6*>(&a.storage_);
    const auto* y = reinterpret_cast<const sockaddr_in6*>(&b.storage_);
    return std::memcmp(&x->sin6_addr, &y->sin6_addr, sizeof(in6_addr)) == 0 && x->sin6_port == y->sin6_port &&
           x->sin6_scope_id == y->sin6_scope_id;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// UdpSocket

UdpSocket::~UdpSocket() { close(); }

UdpSocket::UdpSocket(UdpSocket&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), family_(other.family_), last_error_(other.last_error_.load(std::memory_order_relaxed)) {}

UdpSocket& UdpSocket::operator=(UdpSocket&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    family_ = other.family_;
    last_error_.store(other.last_error_.load(std::memory_order_relaxed), std::memory_order_relaxed);
  }
  return *this;
}

void UdpSocket::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

UdpSocket UdpSocket::open(int family, const SendOptions& options) {
  if (family != AF_INET && family != AF_INET6) throw_errno(EAFNOSUPPORT, "UDP socket: not an IP address family");
  const int fd = ::socket(family, SOCK_DGRAM, 0);
  if (fd < 0) throw_errno(errno, family == AF_INET ? "socket(AF_INET)" : "socket(AF_INET6)");
  UdpSocket s(fd, family);
  if (set_nonblocking_cloexec(fd) != 0) throw_errno(errno, "fcntl(O_NONBLOCK)");
  s.set_multicast_ttl(options.multicast_ttl);
  s.set_multicast_loopback(options.multicast_loopback);
  if (!options.interface.name_or_address.empty()) s.set_multicast_interface(options.interface);
  return s;
}

UdpSocket UdpSocket::bind(const Endpoint& local, const ReceiveOptions& options) {
  UdpSocket s = open(local.family());
  const int on = 1;
  if (options.reuse_address || options.group) set_option(s.fd_, SOL_SOCKET, SO_REUSEADDR, on, "setsockopt(SO_REUSEADDR)");
  if (options.receive_buffer_bytes > 0)
    set_option(s.fd_, SOL_SOCKET, SO_RCVBUF, options.receive_buffer_bytes, "setsockopt(SO_RCVBUF)");
#ifdef IP_MULTICAST_ALL
  if (local.family() == AF_INET && options.group) {
    // Linux delivers every group any socket on the host joined to a wildcard-bound socket;
    // only ours, please. Best effort.
    const int off = 0;
    (void)setsockopt(s.fd_, IPPROTO_IP, IP_MULTICAST_ALL, &off, sizeof off);
  }
#endif
  if (::bind(s.fd_, local.sockaddr_ptr(), local.sockaddr_len()) != 0)
    throw_errno(errno, "cannot bind UDP " + local.to_string());
  if (options.group) s.join_group(*options.group, options.interface);
  return s;
}

Endpoint UdpSocket::local_endpoint() const {
  sockaddr_storage ss{};
  socklen_t len = sizeof ss;
  if (fd_ < 0 || getsockname(fd_, reinterpret_cast<sockaddr*>(&ss), &len) != 0) return {};
  return Endpoint::from_sockaddr(reinterpret_cast<const sockaddr*>(&ss), len);
}

void UdpSocket::join_group(const Endpoint& group, const MulticastInterface& interface) {
  if (!group.is_multicast()) throw_errno(EINVAL, group.address_string() + " is not a multicast address");
  if (group.family() != family_)
    throw_errno(EAFNOSUPPORT, "multicast group " + group.address_string() + " is not of the socket's address family");
  const std::string what = "cannot join multicast group " + group.address_string() +
                           (interface.name_or_address.empty() ? "" : " on " + interface.name_or_address);
  if (family_ == AF_INET) {
    ip_mreqn m = ipv4_interface(interface);
    m.imr_multiaddr = reinterpret_cast<const sockaddr_in*>(group.sockaddr_ptr())->sin_addr;
    set_option(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, m, what);
  } else {
    ipv6_mreq m{};
    m.ipv6mr_multiaddr = reinterpret_cast<const sockaddr_in6*>(group.sockaddr_ptr())->sin6_addr;
    m.ipv6mr_interface = interface_index(interface);
    if (m.ipv6mr_interface == 0) m.ipv6mr_interface = reinterpret_cast<const sockaddr_in6*>(group.sockaddr_ptr())->sin6_scope_id;
    set_option(fd_, IPPROTO_IPV6, IPV6_JOIN_GROUP, m, what);
  }
}

void UdpSocket::set_multicast_ttl(int ttl) {
  if (ttl < 0 || ttl > 255) throw_errno(EINVAL, "multicast TTL must be 0..255");
  if (family_ == AF_INET)
    set_option(fd_, IPPROTO_IP, IP_MULTICAST_TTL, ttl, "setsockopt(IP_MULTICAST_TTL)");
  else
    set_option(fd_, IPPROTO_IPV6, IPV6_MULTICAST_HOPS, ttl, "setsockopt(IPV6_MULTICAST_HOPS)");
}

int UdpSocket::multicast_ttl() const {
  int v = -1;
  socklen_t len = sizeof v;
  if (family_ == AF_INET) {
    // Linux answers with an int; some systems with a byte.
    if (getsockopt(fd_, IPPROTO_IP, IP_MULTICAST_TTL, &v, &len) != 0) return -1;
    if (len == 1) v &= 0xFF;
  } else if (getsockopt(fd_, IPPROTO_IPV6, IPV6_MULTICAST_HOPS, &v, &len) != 0) {
    return -1;
  }
  return v;
}

void UdpSocket::set_multicast_interface(const MulticastInterface& interface) {
  const std::string what = "cannot send multicast from interface " + interface.name_or_address;
  if (family_ == AF_INET) {
    const ip_mreqn m = ipv4_interface(interface);
    set_option(fd_, IPPROTO_IP, IP_MULTICAST_IF, m, what);
  } else {
    const unsigned idx = interface_index(interface);
    set_option(fd_, IPPROTO_IPV6, IPV6_MULTICAST_IF, idx, what);
  }
}

void UdpSocket::set_multicast_loopback(bool on) {
  if (family_ == AF_INET) {
    const unsigned char v = on ? 1 : 0;
    set_option(fd_, IPPROTO_IP, IP_MULTICAST_LOOP, v, "setsockopt(IP_MULTICAST_LOOP)");
  } else {
    const unsigned v = on ? 1 : 0;
    set_option(fd_, IPPROTO_IPV6, IPV6_MULTICAST_LOOP, v, "setsockopt(IPV6_MULTICAST_LOOP)");
  }
}

std::optional<ReceivedDatagram> UdpSocket::receive(std::span<std::uint8_t> buffer, std::chrono::milliseconds timeout) {
  if (fd_ < 0) return std::nullopt;
  pollfd p{fd_, POLLIN, 0};
  const auto ms = std::clamp<std::chrono::milliseconds::rep>(timeout.count(), 0, std::numeric_limits<int>::max());
  const int ready = ::poll(&p, 1, static_cast<int>(ms));
  if (ready <= 0) {
    if (ready < 0) last_error_.store(errno, std::memory_order_relaxed);
    return std::nullopt;
  }
  sockaddr_storage from{};
  iovec iov{buffer.data(), buffer.size()};
  msghdr msg{};
  msg.msg_name = &from;
  msg.msg_namelen = sizeof from;
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  // MSG_TRUNC: Linux returns the datagram's real length even when it did not fit.
  const ssize_t n = ::recvmsg(fd_, &msg, MSG_TRUNC);
  if (n < 0) {
    last_error_.store(errno, std::memory_order_relaxed);
    return std::nullopt;
  }
  ReceivedDatagram d;
  d.received_at = std::chrono::system_clock::now();
  d.size = static_cast<std::size_t>(n);
  d.truncated = (msg.msg_flags & MSG_TRUNC) != 0 || d.size > buffer.size();
  d.source = Endpoint::from_sockaddr(reinterpret_cast<const sockaddr*>(&from), msg.msg_namelen);
  return d;
}

bool UdpSocket::send_to(std::span<const std::uint8_t> datagram, const Endpoint& to) {
  for (;;) {
    const ssize_t n = ::sendto(fd_, datagram.data(), datagram.size(), MSG_NOSIGNAL, to.sockaddr_ptr(), to.sockaddr_len());
    if (n >= 0) return static_cast<std::size_t>(n) == datagram.size();
    if (errno == EINTR) continue;
    last_error_.store(errno, std::memory_order_relaxed);
    return false;
  }
}

// ---------------------------------------------------------------------------------------------
// UdpSender

UdpSender::UdpSender(std::vector<Endpoint> destinations, SendOptions options) : destinations_(std::move(destinations)) {
  const bool need4 = std::any_of(destinations_.begin(), destinations_.end(), [](const Endpoint& e) { return e.family() == AF_INET; });
  const bool need6 = std::any_of(destinations_.begin(), destinations_.end(), [](const Endpoint& e) { return e.family() == AF_INET6; });
  if (need4) v4_ = UdpSocket::open(AF_INET, options);
  if (need6) v6_ = UdpSocket::open(AF_INET6, options);
  batched_ = options.sendmmsg && destinations_.size() > 1;
  for (const Endpoint& to : destinations_) (to.family() == AF_INET ? destinations4_ : destinations6_).push_back(to);
}

// Every destination of one family in as few sendmmsg calls as the kernel allows (the headers in
// chunks on the stack, all pointing at one iovec); a header the kernel refuses is a failed send,
// and the rest are still sent.
std::size_t UdpSender::send_batch(const UdpSocket& socket, std::span<const Endpoint> family_destinations,
                                  std::span<const std::uint8_t> datagram) {
  const std::size_t n = family_destinations.size();
  if (n == 0) return 0;
  if (!socket.is_open()) {
    failures_.fetch_add(n, std::memory_order_relaxed);
    return 0;
  }
  constexpr std::size_t kChunk = 16;
  ::iovec iov{const_cast<std::uint8_t*>(datagram.data()), datagram.size()};  // sendmmsg does not write it
  std::array<::mmsghdr, kChunk> headers{};
  std::size_t ok = 0, failed = 0;
  for (std::size_t first = 0; first < n; first += kChunk) {
    const std::size_t m = std::min(kChunk, n - first);
    for (std::size_t i = 0; i < m; ++i) {
      const Endpoint& to = family_destinations[first + i];
      headers[i] = ::mmsghdr{};
      headers[i].msg_hdr.msg_name = const_cast<sockaddr*>(to.sockaddr_ptr());  // sendmmsg does not write it
      headers[i].msg_hdr.msg_namelen = to.sockaddr_len();
      headers[i].msg_hdr.msg_iov = &iov;
      headers[i].msg_hdr.msg_iovlen = 1;
    }
    for (std::size_t next = 0; next < m;) {
      const int sent = ::sendmmsg(socket.fd(), headers.data() + next, static_cast<unsigned>(m - next), MSG_NOSIGNAL);
      if (sent < 0 && errno == EINTR) continue;
      if (sent <= 0) {  // the header at `next` failed: count it, go on with the next one
        ++failed;
        ++next;
        continue;
      }
      for (int i = 0; i < sent; ++i)
        if (headers[next + static_cast<std::size_t>(i)].msg_len == datagram.size()) ++ok; else ++failed;
      next += static_cast<std::size_t>(sent);
    }
  }
  if (failed) failures_.fetch_add(failed, std::memory_order_relaxed);
  return ok;
}

std::size_t UdpSender::send(std::span<const std::uint8_t> datagram) {
  if (batched_) return send_batch(v4_, destinations4_, datagram) + send_batch(v6_, destinations6_, datagram);
  std::size_t ok = 0;
  for (const Endpoint& to : destinations_) {
    UdpSocket& s = to.family() == AF_INET ? v4_ : v6_;
    if (s.is_open() && s.send_to(datagram, to))
      ++ok;
    else
      failures_.fetch_add(1, std::memory_order_relaxed);
  }
  return ok;
}

}  // namespace posefair::daemon
