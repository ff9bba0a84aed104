#pragma once
// Where a test's poses go: a UDP socket of the test's own on 127.0.0.1, the destination of an
// in-process daemon::Pipeline (tests/daemon/pipeline_tests.cpp) or of a posefaird child process
// (daemon_process.hpp), drained by a thread of its own from the start so the kernel's receive
// buffer never has to hold a whole run, and every datagram decoded (daemon/wire_protocol.hpp)
// with its arrival time. Also the tests' bounded wait.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"

namespace posefair::testing {

class UdpCollector {
 public:
  struct Got {
    daemon::PoseMessage m;
    std::chrono::steady_clock::time_point at;  // arrival
  };

  UdpCollector() {
    daemon::ReceiveOptions ro;
    ro.receive_buffer_bytes = 8 << 20;
    socket_ = daemon::UdpSocket::bind(*daemon::Endpoint::parse("127.0.0.1:0"), ro);
    thread_ = std::thread([this] { loop(); });
  }
  ~UdpCollector() { stop(); }
  UdpCollector(const UdpCollector&) = delete;
  UdpCollector& operator=(const UdpCollector&) = delete;

  std::uint16_t port() const { return socket_.local_endpoint().port(); }

  // Ends the thread once nothing has arrived for `quiet` (bounded by `limit` overall): the
  // caller has stopped the pipeline, so whatever is still in flight is in the socket buffer.
  void drain(std::chrono::milliseconds quiet = std::chrono::milliseconds(300),
             std::chrono::milliseconds limit = std::chrono::seconds(10)) {
    const auto deadline = std::chrono::steady_clock::now() + limit;
    for (;;) {
      const std::size_t before = datagrams();
      std::this_thread::sleep_for(quiet);
      if (datagrams() == before || std::chrono::steady_clock::now() > deadline) break;
    }
    stop();
  }

  // The datagrams that decoded, in arrival order.
  std::vector<daemon::PoseMessage> messages() const {
    std::lock_guard lock(mutex_);
    std::vector<daemon::PoseMessage> out;
    out.reserve(got_.size());
    for (const Got& g : got_) out.push_back(g.m);
    return out;
  }
  // The same with their arrival times.
  std::vector<Got> all() const {
    std::lock_guard lock(mutex_);
    return got_;
  }
  // How many of them belong to `stream`.
  std::size_t count(std::uint32_t stream) const {
    std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(
        std::count_if(got_.begin(), got_.end(), [&](const Got& g) { return g.m.stream == stream; }));
  }
  // How many of them `keep` picks (a stream in a session, say).
  std::size_t count_if(const std::function<bool(const daemon::PoseMessage&)>& keep) const {
    std::lock_guard lock(mutex_);
    return static_cast<std::size_t>(std::count_if(got_.begin(), got_.end(), [&](const Got& g) { return keep(g.m); }));
  }
  // The datagrams that did not (truncated, or refused by the decoder).
  std::size_t malformed() const {
    std::lock_guard lock(mutex_);
    return malformed_;
  }
  // Every datagram received.
  std::size_t datagrams() const {
    std::lock_guard lock(mutex_);
    return got_.size() + malformed_;
  }

 private:
  void stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  void loop() {
    std::vector<std::uint8_t> buffer(daemon::kMaxDatagramSize + 1);
    while (!stop_.load()) {
      const auto d = socket_.receive(buffer, std::chrono::milliseconds(20));
      if (!d) continue;
      const daemon::DecodeResult r =
          d->truncated ? daemon::rejected(daemon::DecodeError::kOversized, daemon::WireEncoding::kBinary)
                       : daemon::decode_datagram(std::span<const std::uint8_t>(buffer.data(), d->size));
      std::lock_guard lock(mutex_);
      if (r.ok())
        got_.push_back(Got{r.message, std::chrono::steady_clock::now()});
      else
        ++malformed_;
    }
  }

  daemon::UdpSocket socket_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::vector<Got> got_;
  std::size_t malformed_ = 0;
};

// Polls `done` every 5 ms until it holds (true) or `timeout` has passed (false).
inline bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

}  // namespace posefair::testing
