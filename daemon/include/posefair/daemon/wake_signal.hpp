#pragma once
// How a producer wakes a sleeping consumer thread (the engine, the publisher): an event count
// on a Linux futex. notify() costs one atomic increment while the consumer is busy and a
// FUTEX_WAKE system call only when it actually sleeps; wait() sleeps in the kernel at once.
// (std::atomic::wait spins and calls sched_yield first, and its notify_one hashes into a
// shared waiter table: on a 2-core virtual machine, measured with `posefair bench latency`,
// that cost more CPU and latency than it saved.)
//
//   consumer:  for (;;) { auto seen = s.prepare(); if (work()) continue; s.wait(seen); }
//   producer:  publish the work (release), then s.notify();
//
// One consumer per signal; any number of producers.
//
// Batched (the default, [daemon] wake = "per-batch"): the consumer sleeps announcing the count
// it saw; only the notify() whose increment is the first one after it (the one that found the
// count at `seen`) makes the FUTEX_WAKE. The notifies of the rest of a burst (16 trackers on
// one sync line, a driver that read several frames) make none, however long the woken thread
// takes to be scheduled. (Taking a plain "sleeping" flag with an exchange instead loses wakes:
// a notifier preempted between its increment and the exchange can take the flag of a later
// sleep that already counted its increment, and its FUTEX_WAKE comes too early for it.)
// Per sample ("per-sample"): every notify() while the consumer sleeps makes a FUTEX_WAKE.
#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>

#include "posefair/daemon/adaptive_spin.hpp"

namespace posefair::daemon {

class WakeSignal {
 public:
  explicit WakeSignal(bool batched = true) : batched_(batched) {}

  // Read before looking for work: a notify() after this makes wait(seen) return at once.
  std::uint32_t prepare() const { return count_.load(std::memory_order_seq_cst); }

  // Sleeps until a notify() that came after prepare() returned `seen` (or spuriously).
  void wait(std::uint32_t seen) {
    sleeping_.store(kSleeping | seen, std::memory_order_seq_cst);
    // Dekker with notify(): either this load sees the producer's increment, or the producer
    // sees sleeping_ and wakes the futex (which itself rechecks the count in the kernel).
    if (count_.load(std::memory_order_seq_cst) == seen)
      ::syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count_), FUTEX_WAIT_PRIVATE, seen, nullptr, nullptr, 0);
    sleeping_.store(0, std::memory_order_relaxed);
  }

  // wait(seen), after spinning (bounded, adaptive) for a notify() that makes parking needless.
  void wait(std::uint32_t seen, AdaptiveSpin& spin) {
    if (spin.spin([&] { return count_.load(std::memory_order_acquire) != seen; })) return;
    wait(seen);
  }

  void notify() {
    const std::uint32_t before = count_.fetch_add(1, std::memory_order_seq_cst);
    const std::uint64_t sleeping = sleeping_.load(std::memory_order_seq_cst);
    // Batched: only the first increment the sleeper has not seen wakes it (a stale notifier,
    // whose increment the sleeper already counted, finds a different count there).
    if (batched_ ? sleeping == (kSleeping | before) : (sleeping & kSleeping) != 0)
      ::syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count_), FUTEX_WAKE_PRIVATE, 1, nullptr, nullptr, 0);
  }

 private:
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));
  static constexpr std::uint64_t kSleeping = std::uint64_t{1} << 32;
  alignas(64) std::atomic<std::uint32_t> count_{0};
  std::atomic<std::uint64_t> sleeping_{0};  // kSleeping | the count the sleeper saw; 0 while awake
  bool batched_;
};

}  // namespace posefair::daemon
