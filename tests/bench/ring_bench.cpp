// SpscRing (both overflow policies) against boost::lockfree::spsc_queue, carrying a 128-byte
// Sample-like item, capacity 1024 each.
// - SingleThread: one thread pushes then pops (one item, or a burst of 256): the cost of the
//   operations themselves, no cache-line traffic between cores.
// - TwoThreads: the benchmark thread pushes, a consumer thread pops as fast as it can. "retry"
//   spins on a refused push (lossless: the transfer rate); "drop" gives up on a refused push;
//   DropOldest never refuses. The counter `delivered` is the fraction of pushes the consumer got.
// Run: build/tests/bench/ring_bench
#include <benchmark/benchmark.h>

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <memory>
#include <thread>

#include "posefair/daemon/spsc_ring.hpp"

namespace posefair::daemon {
namespace {

struct Payload {  // the size of a Sample plus room, trivially copyable
  std::uint64_t sequence;
  std::uint32_t stream_id;
  std::uint32_t flags;
  double time[3];
  double orientation[4];
  double position[3];
  double spare[4];
};
static_assert(sizeof(Payload) == 128);

constexpr std::size_t kCapacity = 1024;

enum class Kind { RingDropOldest, RingDropNewest, Boost };

using BoostQueue = boost::lockfree::spsc_queue<Payload>;

// The queue kind is a template argument: no dispatch inside the measurement.
template <Kind K>
struct Typed;
template <>
struct Typed<Kind::RingDropOldest> {
  SpscRing<Payload> q{kCapacity, OverflowPolicy::DropOldest};
};
template <>
struct Typed<Kind::RingDropNewest> {
  SpscRing<Payload> q{kCapacity, OverflowPolicy::DropNewest};
};
template <>
struct Typed<Kind::Boost> {
  BoostQueue q{kCapacity};
};

template <Kind K>
void single_thread(benchmark::State& state) {
  auto holder = std::make_unique<Typed<K>>();
  auto& q = holder->q;
  const auto burst = static_cast<std::uint64_t>(state.range(0));
  Payload in{};
  Payload out{};
  for (auto _ : state) {
    for (std::uint64_t i = 0; i < burst; ++i) {
      in.sequence = i;
      benchmark::DoNotOptimize(q.push(in));
    }
    for (std::uint64_t i = 0; i < burst; ++i) {
      benchmark::DoNotOptimize(q.pop(out));
      benchmark::DoNotOptimize(out);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(burst));
}

template <Kind K, bool kRetry>
void two_threads(benchmark::State& state) {
  auto holder = std::make_unique<Typed<K>>();
  auto& q = holder->q;
  std::atomic<bool> stop{false};
  std::uint64_t received = 0;
  std::thread consumer([&] {
    Payload out{};
    std::uint64_t n = 0;
    while (!stop.load(std::memory_order_relaxed)) {
      if (q.pop(out)) {
        ++n;
        benchmark::DoNotOptimize(out);
      }
    }
    while (q.pop(out)) ++n;
    received = n;
  });
  Payload in{};
  std::uint64_t seq = 0;
  for (auto _ : state) {
    in.sequence = seq++;
    if constexpr (kRetry) {
      while (!q.push(in)) {
      }
    } else {
      benchmark::DoNotOptimize(q.push(in));
    }
  }
  stop.store(true, std::memory_order_relaxed);
  consumer.join();
  state.SetItemsProcessed(state.iterations());
  state.counters["delivered"] = static_cast<double>(received) / static_cast<double>(seq);
}

BENCHMARK(single_thread<Kind::RingDropOldest>)->Arg(1)->Arg(256);
BENCHMARK(single_thread<Kind::RingDropNewest>)->Arg(1)->Arg(256);
BENCHMARK(single_thread<Kind::Boost>)->Arg(1)->Arg(256);
BENCHMARK(two_threads<Kind::RingDropOldest, false>)->UseRealTime();
BENCHMARK(two_threads<Kind::RingDropNewest, true>)->UseRealTime();
BENCHMARK(two_threads<Kind::Boost, true>)->UseRealTime();
BENCHMARK(two_threads<Kind::RingDropNewest, false>)->UseRealTime();
BENCHMARK(two_threads<Kind::Boost, false>)->UseRealTime();

}  // namespace
}  // namespace posefair::daemon

BENCHMARK_MAIN();
