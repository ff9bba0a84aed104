#pragma once
// A small RAII POSIX UDP socket for the wire protocol: bind and receive (unicast, or a
// multicast group joined on an interface), non-blocking receive with a poll timeout that
// reports truncated (oversized) datagrams, and sending one datagram to a list of destinations
// (unicast and multicast; multicast TTL 1 unless configured, outgoing interface selectable).
// IPv4 and IPv6. Errors at set-up throw std::system_error (errno as the code) with a message
// naming the address; the receive and send paths never throw.
#include <sys/socket.h>
#include <sys/uio.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace posefair::daemon {

// An IPv4 or IPv6 address with a port.
class Endpoint {
 public:
  Endpoint() = default;
  // "ADDR:PORT" with ADDR a numeric IPv4 address, or "[ADDR]:PORT" with a numeric IPv6
  // address (an "%iface" zone allowed). With default_port, "ADDR" / "[ADDR]" / a bare IPv6
  // address alone are accepted too. No name lookup. nullopt if malformed.
  static std::optional<Endpoint> parse(std::string_view text, std::optional<std::uint16_t> default_port = {});
  // A numeric address without port ("239.255.0.1", "ff02::1"), port 0.
  static std::optional<Endpoint> parse_address(std::string_view text);
  static Endpoint from_sockaddr(const sockaddr* sa, socklen_t len);

  int family() const { return storage_.ss_family; }  // AF_INET or AF_INET6 (AF_UNSPEC if empty)
  std::uint16_t port() const;
  void set_port(std::uint16_t port);
  bool is_multicast() const;
  bool is_unspecified() const;  // 0.0.0.0 or ::
  std::string to_string() const;  // "1.2.3.4:5" or "[::1]:5"
  std::string address_string() const;

  const sockaddr* sockaddr_ptr() const { return reinterpret_cast<const sockaddr*>(&storage_); }
  socklen_t sockaddr_len() const { return len_; }

  friend bool operator==(const Endpoint& a, const Endpoint& b);

 private:
  sockaddr_storage storage_{};
  socklen_t len_ = 0;
};

// Where a multicast group is joined, or multicast is sent from: an interface given by a
// local IPv4 address ("192.168.1.10") or by name ("eth0"). Empty = the kernel's choice.
struct MulticastInterface {
  std::string name_or_address;
};

struct ReceiveOptions {
  std::optional<Endpoint> group;  // join this multicast group (same family as the bound address)
  MulticastInterface interface;
  // SO_REUSEADDR, so several subscribers of one multicast group can share a port on a host.
  // Always on when group is set; off otherwise (two unicast receivers on one port would
  // silently steal each other's datagrams).
  bool reuse_address = false;
  int receive_buffer_bytes = 0;  // SO_RCVBUF if > 0
};

struct SendOptions {
  int multicast_ttl = 1;  // IP_MULTICAST_TTL / IPV6_MULTICAST_HOPS: 1 = this link only
  MulticastInterface interface;  // outgoing interface for multicast
  bool multicast_loopback = true;  // IP_MULTICAST_LOOP: local subscribers see our multicast
  bool sendmmsg = true;  // UdpSender: one sendmmsg per family for several destinations, not a sendto each
};

struct ReceivedDatagram {
  std::size_t size = 0;     // the datagram's real size (may exceed the buffer)
  bool truncated = false;   // it did not fit into the buffer: only the first bytes are there
  Endpoint source;
  std::chrono::system_clock::time_point received_at;  // CLOCK_REALTIME right after receipt
};

class UdpSocket {
 public:
  UdpSocket() = default;
  ~UdpSocket();
  UdpSocket(UdpSocket&& other) noexcept;
  UdpSocket& operator=(UdpSocket&& other) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  // A non-blocking socket bound to local (port 0 = any free port); joins options.group if set.
  static UdpSocket bind(const Endpoint& local, const ReceiveOptions& options = {});
  // A non-blocking unbound socket of the family (AF_INET / AF_INET6) for sending.
  static UdpSocket open(int family, const SendOptions& options = {});

  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  int family() const { return family_; }
  Endpoint local_endpoint() const;  // the bound address, with the port the kernel chose

  void join_group(const Endpoint& group, const MulticastInterface& interface = {});
  void set_multicast_ttl(int ttl);
  int multicast_ttl() const;
  void set_multicast_interface(const MulticastInterface& interface);
  void set_multicast_loopback(bool on);

  // Waits up to timeout for a datagram and reads it into buffer. nullopt on timeout, on a
  // signal (EINTR), or on a transient error (the caller just loops). A datagram larger than
  // buffer is consumed whole and reported with truncated = true and its real size.
  std::optional<ReceivedDatagram> receive(std::span<std::uint8_t> buffer, std::chrono::milliseconds timeout);

  // Sends one datagram; false (and errno kept in last_error()) on failure. Several threads may
  // send on one socket at once (each stream's engine role publishes its own poses).
  bool send_to(std::span<const std::uint8_t> datagram, const Endpoint& to);
  int last_error() const { return last_error_.load(std::memory_order_relaxed); }

 private:
  UdpSocket(int fd, int family) : fd_(fd), family_(family) {}
  void close();

  int fd_ = -1;
  int family_ = 0;
  std::atomic<int> last_error_{0};
};

// One datagram to a list of destinations, IPv4 and IPv6 mixed (one socket per family the list
// needs, opened by the constructor, which throws std::system_error if it cannot). send() never
// throws; failed sends are counted. With SendOptions::sendmmsg, the destinations of one family
// are sent to in one sendmmsg(2) call (one system call instead of one per destination; the
// message headers are built on the stack per call). send() may run on several threads at once.
class UdpSender {
 public:
  explicit UdpSender(std::vector<Endpoint> destinations, SendOptions options = {});
  UdpSender(UdpSender&& other) noexcept
      : destinations_(std::move(other.destinations_)),
        destinations4_(std::move(other.destinations4_)),
        destinations6_(std::move(other.destinations6_)),
        v4_(std::move(other.v4_)),
        v6_(std::move(other.v6_)),
        batched_(other.batched_),
        failures_(other.failures_.load(std::memory_order_relaxed)) {}
  // Sends to every destination in order; returns how many sends succeeded.
  std::size_t send(std::span<const std::uint8_t> datagram);
  const std::vector<Endpoint>& destinations() const { return destinations_; }
  std::uint64_t failures() const { return failures_.load(std::memory_order_relaxed); }

 private:
  std::size_t send_batch(const UdpSocket& socket, std::span<const Endpoint> family_destinations, std::span<const std::uint8_t> datagram);

  std::vector<Endpoint> destinations_;
  std::vector<Endpoint> destinations4_, destinations6_;  // by family, for sendmmsg
  UdpSocket v4_, v6_;
  bool batched_ = false;
  std::atomic<std::uint64_t> failures_{0};
};

}  // namespace posefair::daemon
