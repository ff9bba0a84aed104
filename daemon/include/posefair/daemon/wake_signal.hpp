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
#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>

namespace posefair::daemon {

class WakeSignal {
 public:
  // Read before looking for work: a notify() after this makes wait(seen) return at once.
  std::uint32_t prepare() const { return count_.load(std::memory_order_seq_cst); }

  // Sleeps until a notify() that came after prepare() returned `seen` (or spuriously).
  void wait(std::uint32_t seen) {
    sleeping_.store(true, std::memory_order_seq_cst);
    // Dekker with notify(): either this load sees the producer's increment, or the producer
    // sees sleeping_ and wakes the futex (which itself rechecks the count in the kernel).
    if (count_.load(std::memory_order_seq_cst) == seen)
      ::syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count_), FUTEX_WAIT_PRIVATE, seen, nullptr, nullptr, 0);
    sleeping_.store(false, std::memory_order_relaxed);
  }

  void notify() {
    count_.fetch_add(1, std::memory_order_seq_cst);
    if (sleeping_.load(std::memory_order_seq_cst))
      ::syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&count_), FUTEX_WAKE_PRIVATE, 1, nullptr, nullptr, 0);
  }

 private:
  static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));
  alignas(64) std::atomic<std::uint32_t> count_{0};
  std::atomic<bool> sleeping_{false};
};

}  // namespace posefair::daemon
