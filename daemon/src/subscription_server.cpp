#include "posefair/daemon/subscription_server.hpp"

#include <pthread.h>

#include <chrono>
#include <vector>

namespace posefair::daemon {
namespace {
std::chrono::nanoseconds steady_now() { return std::chrono::steady_clock::now().time_since_epoch(); }

// A deeper queue than the default, so a burst waits for the thread instead of being dropped
// (the kernel caps it at net.core.rmem_max).
ReceiveOptions receive_options() {
  ReceiveOptions o;
  o.receive_buffer_bytes = 1 << 20;
  return o;
}
}  // namespace

SubscriptionServer::SubscriptionServer(SubscriptionSettings settings)
    : table_(std::make_shared<SubscriberTable>(settings.max_subscribers, settings.max_per_address)),
      handler_(settings, table_),
      socket_(UdpSocket::bind(settings.listen, receive_options())) {}

SubscriptionServer::~SubscriptionServer() { stop(); }

void SubscriptionServer::start() {
  if (thread_.joinable()) return;
  stop_.store(false, std::memory_order_relaxed);
  thread_ = std::thread([this] { serve(); });
}

void SubscriptionServer::stop() {
  stop_.store(true, std::memory_order_relaxed);
  if (thread_.joinable()) thread_.join();
}

void SubscriptionServer::serve() {
  ::pthread_setname_np(::pthread_self(), "pf-subscribe");
  std::vector<std::uint8_t> buffer(kMaxDatagramSize + 1);
  auto next_expiry = steady_now();
  while (!stop_.load(std::memory_order_relaxed)) {
    const auto d = socket_.receive(buffer, std::chrono::milliseconds(100));
    const auto now = steady_now();
    if (d) {
      // A truncated datagram is oversized: the parser sees it whole-sized and refuses it.
      const std::size_t size = d->truncated ? buffer.size() : d->size;
      if (const auto reply = handler_.handle(std::span<const std::uint8_t>(buffer.data(), size), d->source, now))
        socket_.send_to(*reply, d->source);
    }
    if (now >= next_expiry) {
      handler_.expire(now);
      next_expiry = now + std::chrono::milliseconds(100);
    }
  }
}

}  // namespace posefair::daemon
