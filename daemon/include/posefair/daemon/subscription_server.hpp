#pragma once
// The subscription port: a UDP socket on [subscription] listen and the thread that serves it
// ("pf-subscribe"), apart from the real-time threads. Each datagram goes through the
// SubscriptionHandler (allow list, rate limits, cookies, the subscriber table) and its reply,
// if any, back to the source; every 100 ms the leases that ran out are ended. The publisher
// finds the subscribers through table(). One server lives as long as posefaird: subscriptions
// survive a reload.
#include <atomic>
#include <memory>
#include <thread>

#include "posefair/daemon/subscription_handler.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::daemon {

class SubscriptionServer {
 public:
  // Binds the port now (std::system_error if it cannot); serves after start().
  explicit SubscriptionServer(SubscriptionSettings settings);
  ~SubscriptionServer();
  SubscriptionServer(const SubscriptionServer&) = delete;
  SubscriptionServer& operator=(const SubscriptionServer&) = delete;

  void start();
  void stop();
  Endpoint local_endpoint() const { return socket_.local_endpoint(); }
  std::shared_ptr<SubscriberTable> table() const { return table_; }
  SubscriptionHandler& handler() { return handler_; }
  const SubscriptionHandler& handler() const { return handler_; }

 private:
  void serve();
  std::shared_ptr<SubscriberTable> table_;
  SubscriptionHandler handler_;
  UdpSocket socket_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace posefair::daemon
