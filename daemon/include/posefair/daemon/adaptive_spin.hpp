#pragma once
// A bounded, adaptive spin before a consumer thread parks on its WakeSignal ([daemon] spin_us,
// docs/config.md). On a virtual machine a parked thread can take milliseconds to run again
// (docs/benchmarks.md, "Latency by stage"); spinning a little while for the next item avoids
// the park and the wake-up system call on the producer's side, at the price of the CPU spun.
//
// Adaptive: the budget starts at the bound; a spin that ends in work keeps it (doubling it back
// towards the bound), a spin that runs out halves it, down to 1/16 of the bound. A stream that
// pauses for long costs 1/16 of the bound per park instead of the whole bound; a steady stream
// whose next sample comes within the bound never parks at all.
#include <chrono>
#include <cstdint>
#include <ctime>

namespace posefair::daemon {

// One pause of a spin loop: tells the CPU (and a hypervisor's pause-loop detection) that this
// is a spin, and saves power and the sibling hyper-thread's cycles.
inline void cpu_relax() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield" ::: "memory");
#endif
}

class AdaptiveSpin {
 public:
  explicit AdaptiveSpin(std::chrono::nanoseconds bound = std::chrono::nanoseconds(0))
      : bound_ns_(static_cast<std::uint64_t>(bound.count())), budget_ns_(bound_ns_) {}

  bool enabled() const { return bound_ns_ > 0; }
  std::uint64_t budget_ns() const { return budget_ns_; }

  // Spins until done() is true (returns true) or the budget runs out (false); adapts the budget.
  template <class Done>
  bool spin(Done&& done) {
    if (bound_ns_ == 0) return false;
    const std::uint64_t start = now_ns();
    for (unsigned i = 0;; ++i) {
      if (done()) {
        budget_ns_ = budget_ns_ * 2 > bound_ns_ ? bound_ns_ : budget_ns_ * 2;
        return true;
      }
      cpu_relax();
      // Read the clock every 16 pauses: a pause is tens of ns, the budget microseconds.
      if ((i & 15) == 15 && now_ns() - start >= budget_ns_) break;
    }
    budget_ns_ = budget_ns_ / 2 < bound_ns_ / 16 ? bound_ns_ / 16 : budget_ns_ / 2;
    return false;
  }

 private:
  static std::uint64_t now_ns() {
    timespec ts{};
    ::clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000u + static_cast<std::uint64_t>(ts.tv_nsec);
  }

  std::uint64_t bound_ns_;
  std::uint64_t budget_ns_;
};

}  // namespace posefair::daemon
