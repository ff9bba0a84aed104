#pragma once
// The clients that signed themselves up for poses (docs/protocol.md, "Subscribing"): one entry
// per address and port, with the encoding and streams it asked for and the end of its lease.
// Capped in total and per address; memory is allocated once, at construction.
//
// Two sides: the control thread adds, renews, removes and expires entries under a mutex; the
// publisher (a real-time thread) never waits for it: refresh() copies the entries into the
// publisher's own preallocated view only when they changed and the mutex is free at once
// (try_lock), and otherwise keeps the view it has. The publisher also skips an entry whose lease
// has run out, so a lease ends on time even when the control thread is late to expire it.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "posefair/daemon/output_encoder.hpp"
#include "posefair/daemon/subscription_message.hpp"
#include "posefair/daemon/udp_socket.hpp"

namespace posefair::daemon {

struct Subscriber {
  Endpoint address;                 // where poses go: the address and port that echoed the cookie
  std::uint8_t encoding = 0;        // index into output_encoder_entries()
  bool angular_velocity = false;
  std::uint8_t stream_count = 0;    // 0: every stream
  std::array<std::uint32_t, kMaxRequestStreams> streams{};
  std::int64_t since_ns = 0;        // steady clock: first subscribed
  std::int64_t expires_ns = 0;      // steady clock: the lease's end
  std::uint32_t last_request_id = 0;
  bool carries(std::uint32_t stream) const;
};

// A subscriber may ask for an encoding that needs nothing configured: no [[output]] options
// (vmc's bones, vrchat's trackers are the operator's to set) and no transport of its own (dds).
inline bool offered_to_subscribers(const OutputEncoderEntry& e) { return e.options.empty() && !e.own_transport; }

class SubscriberTable {
 public:
  // capacity: subscribers in all; per_address: of them from one IP address (any ports).
  SubscriberTable(std::size_t capacity, std::size_t per_address);

  enum class Outcome { Added, Renewed, Replayed, TableFull, AddressFull };
  // Adds s, or renews the entry of its address and port. A renewal must carry a request id
  // above the last one accepted (a replayed request is refused: Replayed).
  Outcome subscribe(const Subscriber& s);
  // Removes the entry of the address and port; false if there is none or the request id is not new.
  bool unsubscribe(const Endpoint& address, std::uint32_t request_id);
  // Removes entries whose lease ended before now; returns how many.
  std::size_t expire(std::int64_t now_ns);

  struct Listed {
    Subscriber subscriber;
    std::uint64_t sent = 0;  // datagrams the publisher sent it
  };
  std::vector<Listed> list() const;
  std::size_t size() const;
  std::size_t capacity() const { return slots_.size(); }
  // The encoder of each registered encoding a subscriber may ask for (offered_to_subscribers),
  // with its default options, built once here; null for the others.
  std::span<const std::shared_ptr<const OutputEncoder>> encoders() const { return encoders_; }

  // --- the publisher's side (never blocks, never allocates) ---
  struct View {
    std::vector<Subscriber> entries;  // capacity() elements, allocated by make_view()
    std::vector<std::uint32_t> slot;  // the table slot of each entry (for count_sent)
    std::size_t count = 0;
    std::uint64_t generation = ~std::uint64_t{0};
  };
  // The publisher's view, allocated and filled now (not on the real-time thread: it waits for the lock).
  View make_view() const;
  // Brings v up to date when the table changed and its lock is free; otherwise leaves it.
  void refresh(View& v) const;
  void count_sent(std::uint32_t slot, std::uint64_t n) { sent_[slot].fetch_add(n, std::memory_order_relaxed); }

 private:
  void copy_locked(View& v) const;  // with mutex_ held

  std::vector<Subscriber> slots_;
  std::vector<char> used_;
  std::unique_ptr<std::atomic<std::uint64_t>[]> sent_;
  std::size_t per_address_;
  std::vector<std::shared_ptr<const OutputEncoder>> encoders_;
  mutable std::mutex mutex_;
  std::atomic<std::uint64_t> generation_{0};
};

}  // namespace posefair::daemon
