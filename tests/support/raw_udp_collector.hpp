#pragma once
// Every datagram reaching a socket of the test's own on 127.0.0.1 (port chosen by the kernel),
// kept as bytes: for the encodings posefair's decoder does not read (opentrack, FreeD, OSC).
// Drained by a thread of its own from the start, like UdpCollector.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::testing {

class RawUdpCollector {
 public:
  RawUdpCollector() : socket_(daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"), {})) {
    thread_ = std::thread([this] {
      std::vector<std::uint8_t> buffer(daemon::kMaxDatagramSize + 1);
      while (!stop_.load()) {
        const auto d = socket_.receive(buffer, std::chrono::milliseconds(20));
        if (!d) continue;
        std::lock_guard lock(mutex_);
        got_.emplace_back(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(d->size));
      }
    });
  }
  ~RawUdpCollector() {
    stop_.store(true);
    thread_.join();
  }
  RawUdpCollector(const RawUdpCollector&) = delete;
  RawUdpCollector& operator=(const RawUdpCollector&) = delete;

  std::uint16_t port() const { return socket_.local_endpoint().port(); }
  std::vector<std::vector<std::uint8_t>> datagrams() const {
    std::lock_guard lock(mutex_);
    return got_;
  }

 private:
  daemon::UdpSocket socket_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::vector<std::vector<std::uint8_t>> got_;
};

}  // namespace posefair::testing
