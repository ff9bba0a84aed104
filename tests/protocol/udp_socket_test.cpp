// The RAII UDP socket, on the loopback interface only (127.0.0.1; ::1 for the IPv6 case;
// multicast only on lo with TTL 0). Every wait is bounded.
#include "posefair/daemon/udp_socket.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <string>
#include <system_error>
#include <vector>

namespace posefair::daemon {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

Endpoint loopback_any_port() { return *Endpoint::parse("127.0.0.1:0"); }

Bytes bytes(const std::string& s) { return Bytes(s.begin(), s.end()); }

// Receives one datagram within 2 s or fails.
std::string receive_string(UdpSocket& s, std::size_t buffer_size = 2048) {
  Bytes buf(buffer_size);
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  while (std::chrono::steady_clock::now() < deadline) {
    if (auto d = s.receive(buf, 100ms)) return std::string(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(std::min(d->size, buf.size())));
  }
  ADD_FAILURE() << "no datagram within 2 s";
  return {};
}

TEST(Endpoint, ParsesIpv4AndIpv6WithPorts) {
  auto a = Endpoint::parse("127.0.0.1:5700");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->family(), AF_INET);
  EXPECT_EQ(a->port(), 5700);
  EXPECT_EQ(a->to_string(), "127.0.0.1:5700");
  EXPECT_FALSE(a->is_multicast());
  auto b = Endpoint::parse("[::1]:65535");
  ASSERT_TRUE(b);
  EXPECT_EQ(b->family(), AF_INET6);
  EXPECT_EQ(b->port(), 65535);
  EXPECT_EQ(b->to_string(), "[::1]:65535");
  auto c = Endpoint::parse("239.255.80.70", 5700);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->port(), 5700);
  EXPECT_TRUE(c->is_multicast());
  EXPECT_TRUE(Endpoint::parse("ff12::5700", 1)->is_multicast());
  EXPECT_TRUE(Endpoint::parse("0.0.0.0:1")->is_unspecified());
  EXPECT_TRUE(Endpoint::parse("[::]:1")->is_unspecified());
  EXPECT_EQ(*Endpoint::parse("127.0.0.1:5"), *Endpoint::parse("127.0.0.1:5"));
  EXPECT_FALSE(*Endpoint::parse("127.0.0.1:5") == *Endpoint::parse("127.0.0.1:6"));
  EXPECT_TRUE(Endpoint::parse_address("239.1.2.3")->is_multicast());
  EXPECT_TRUE(Endpoint::parse_address("ff02::1")->is_multicast());
}

TEST(Endpoint, RejectsMalformedText) {
  for (const char* s : {"", ":", "127.0.0.1", "127.0.0.1:", "127.0.0.1:65536", "127.0.0.1:-1", "127.0.0.1:80x",
                        "127.1:80", "localhost:80", "256.0.0.1:1", "[::1", "[::1]80", "[127.0.0.1]:80", "::1:80:x",
                        "1.2.3.4:5:6"}) {
    EXPECT_FALSE(Endpoint::parse(s)) << s;
  }
  EXPECT_FALSE(Endpoint::parse_address("1.2.3.4:5"));
  EXPECT_FALSE(Endpoint::parse_address("[::1]"));
}

TEST(UdpSocket, SendsAndReceivesOnLoopback) {
  UdpSocket rx = UdpSocket::bind(loopback_any_port());
  const Endpoint to = rx.local_endpoint();
  ASSERT_NE(to.port(), 0);
  UdpSocket tx = UdpSocket::open(AF_INET);
  ASSERT_TRUE(tx.send_to(bytes("hello"), to));
  Bytes buf(64);
  std::optional<ReceivedDatagram> d;
  for (int i = 0; i < 20 && !d; ++i) d = rx.receive(buf, 100ms);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->size, 5u);
  EXPECT_FALSE(d->truncated);
  EXPECT_EQ(std::string(buf.begin(), buf.begin() + 5), "hello");
  EXPECT_EQ(d->source.address_string(), "127.0.0.1");
  const auto age = std::chrono::system_clock::now() - d->received_at;
  EXPECT_GE(age, 0s);
  EXPECT_LT(age, 5s);
}

TEST(UdpSocket, ReceiveTimesOutWithoutTraffic) {
  UdpSocket rx = UdpSocket::bind(loopback_any_port());
  Bytes buf(64);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(rx.receive(buf, 50ms));
  const auto waited = std::chrono::steady_clock::now() - t0;
  EXPECT_GE(waited, 40ms);
  EXPECT_LT(waited, 2s);
}

TEST(UdpSocket, ReportsTruncatedDatagramsWithTheirRealSize) {
  UdpSocket rx = UdpSocket::bind(loopback_any_port());
  UdpSocket tx = UdpSocket::open(AF_INET);
  ASSERT_TRUE(tx.send_to(Bytes(3000, 0x5A), rx.local_endpoint()));
  ASSERT_TRUE(tx.send_to(bytes("next"), rx.local_endpoint()));
  Bytes buf(1501);
  std::optional<ReceivedDatagram> d;
  for (int i = 0; i < 20 && !d; ++i) d = rx.receive(buf, 100ms);
  ASSERT_TRUE(d);
  EXPECT_TRUE(d->truncated);
  EXPECT_EQ(d->size, 3000u);
  // The rest of the big datagram is gone; the next receive gets the next datagram.
  EXPECT_EQ(receive_string(rx), "next");
}

TEST(UdpSocket, BindFailureThrowsSystemErrorNamingTheAddress) {
  UdpSocket first = UdpSocket::bind(loopback_any_port());
  const Endpoint taken = first.local_endpoint();
  try {
    UdpSocket second = UdpSocket::bind(taken);
    FAIL() << "bound " << taken.to_string() << " twice";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code().value(), EADDRINUSE);
    EXPECT_NE(std::string(e.what()).find(taken.to_string()), std::string::npos) << e.what();
  }
}

TEST(UdpSocket, MoveTransfersOwnership) {
  UdpSocket a = UdpSocket::bind(loopback_any_port());
  const int fd = a.fd();
  UdpSocket b = std::move(a);
  EXPECT_FALSE(a.is_open());  // NOLINT(bugprone-use-after-move): moved-from state is specified
  EXPECT_EQ(b.fd(), fd);
  UdpSocket c;
  c = std::move(b);
  EXPECT_EQ(c.fd(), fd);
  EXPECT_TRUE(c.is_open());
}

TEST(UdpSocket, MulticastTtlDefaultsToOneAndIsSettable) {
  UdpSocket s = UdpSocket::open(AF_INET);
  EXPECT_EQ(s.multicast_ttl(), 1);
  s.set_multicast_ttl(4);
  EXPECT_EQ(s.multicast_ttl(), 4);
  SendOptions o;
  o.multicast_ttl = 0;
  EXPECT_EQ(UdpSocket::open(AF_INET, o).multicast_ttl(), 0);
  EXPECT_THROW(s.set_multicast_ttl(256), std::system_error);
  o.multicast_ttl = 1;
  o.interface.name_or_address = "no-such-interface0";
  EXPECT_THROW(UdpSocket::open(AF_INET, o), std::system_error);
}

TEST(UdpSocket, JoinRejectsNonMulticastAndWrongFamily) {
  UdpSocket s = UdpSocket::bind(loopback_any_port());
  EXPECT_THROW(s.join_group(*Endpoint::parse_address("10.1.2.3")), std::system_error);
  EXPECT_THROW(s.join_group(*Endpoint::parse_address("ff02::1")), std::system_error);
}

TEST(UdpSender, SendsOneDatagramToEveryDestination) {
  UdpSocket a = UdpSocket::bind(loopback_any_port());
  UdpSocket b = UdpSocket::bind(loopback_any_port());
  UdpSender sender({a.local_endpoint(), b.local_endpoint()});
  EXPECT_EQ(sender.destinations().size(), 2u);
  EXPECT_EQ(sender.send(bytes("pose")), 2u);
  EXPECT_EQ(receive_string(a), "pose");
  EXPECT_EQ(receive_string(b), "pose");
  EXPECT_EQ(sender.failures(), 0u);
}

// Several destinations of one family go out in one sendmmsg(2) (SendOptions::sendmmsg, the
// default), or one sendto each: every destination gets the datagram once, either way, and a
// mixed IPv4/IPv6 list is sent per family.
TEST(UdpSender, SendmmsgAndSendtoReachEveryDestinationOnce) {
  for (const bool batched : {true, false}) {
    SCOPED_TRACE(batched ? "sendmmsg" : "sendto");
    std::vector<UdpSocket> rx;
    std::vector<Endpoint> to;
    for (int i = 0; i < 5; ++i) {
      rx.push_back(UdpSocket::bind(loopback_any_port()));
      to.push_back(rx.back().local_endpoint());
    }
    bool six = true;
    try {
      rx.push_back(UdpSocket::bind(*Endpoint::parse("[::1]:0")));
      to.insert(to.begin() + 2, rx.back().local_endpoint());  // between the IPv4 ones
    } catch (const std::system_error&) {
      six = false;  // no IPv6 loopback here: IPv4 only
    }
    SendOptions so;
    so.sendmmsg = batched;
    UdpSender sender(to, so);
    for (const char* text : {"one", "two"}) EXPECT_EQ(sender.send(bytes(text)), to.size());
    for (UdpSocket& r : rx) {
      EXPECT_EQ(receive_string(r), "one");
      EXPECT_EQ(receive_string(r), "two");
      Bytes buf(16);
      EXPECT_FALSE(r.receive(buf, 20ms).has_value()) << "a destination got a datagram twice";
    }
    EXPECT_EQ(sender.failures(), 0u);
    EXPECT_EQ(rx.size(), six ? 6u : 5u);
  }
}

TEST(UdpSocket, Ipv6Loopback) {
  UdpSocket rx;
  try {
    rx = UdpSocket::bind(*Endpoint::parse("[::1]:0"));
  } catch (const std::system_error& e) {
    GTEST_SKIP() << "no IPv6 loopback here: " << e.what();
  }
  UdpSender sender({rx.local_endpoint()});
  EXPECT_EQ(sender.send(bytes("six")), 1u);
  EXPECT_EQ(receive_string(rx), "six");
}

// Multicast on the loopback interface only: joined on 127.0.0.1, sent from 127.0.0.1 with
// TTL 0, so nothing leaves the host.
TEST(UdpSocket, MulticastOnLoopbackInterface) {
  const Endpoint group = *Endpoint::parse("239.255.80.71:0");
  ReceiveOptions ro;
  ro.group = group;
  ro.interface.name_or_address = "127.0.0.1";
  UdpSocket rx;
  try {
    rx = UdpSocket::bind(*Endpoint::parse("0.0.0.0:0"), ro);
  } catch (const std::system_error& e) {
    if (e.code().value() == ENODEV || e.code().value() == EADDRNOTAVAIL || e.code().value() == ENOBUFS)
      GTEST_SKIP() << "no multicast on lo here: " << e.what();
    throw;
  }
  Endpoint to = group;
  to.set_port(rx.local_endpoint().port());
  SendOptions so;
  so.multicast_ttl = 0;
  so.interface.name_or_address = "127.0.0.1";
  UdpSender sender({to}, so);
  EXPECT_EQ(sender.send(bytes("group")), 1u);
  EXPECT_EQ(receive_string(rx), "group");
}

}  // namespace
}  // namespace posefair::daemon
