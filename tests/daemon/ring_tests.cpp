// SpscRing: single-thread semantics of both overflow policies (FIFO order, capacity
// boundaries, which items survive, exact loss counts) and two-thread stress tests (1e6
// numbered items, a consumer that pauses now and then, a third thread reading the counters):
// items arrive in increasing order, never torn, and every item is accounted for exactly once.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <thread>
#include <vector>

#include "posefair/daemon/spsc_ring.hpp"

namespace posefair::daemon {
namespace {

// 128 bytes, like a Sample: every word carries the item's number, each differently scrambled,
// so a copy mixing two items is caught.
struct Item {
  std::uint64_t w[16];
};
static_assert(sizeof(Item) == 128);

constexpr std::uint64_t scramble(std::uint64_t n, std::size_t k) {
  return (n + k) * 0x9E3779B97F4A7C15ull ^ (std::uint64_t{k} << 56);
}

Item make_item(std::uint64_t n) {
  Item it;
  for (std::size_t k = 0; k < 16; ++k) it.w[k] = scramble(n, k);
  it.w[0] = n;
  return it;
}

// The item's number if all its words agree, else ~0.
std::uint64_t number_of(const Item& it) {
  const std::uint64_t n = it.w[0];
  for (std::size_t k = 1; k < 16; ++k)
    if (it.w[k] != scramble(n, k)) return ~std::uint64_t{0};
  return n;
}

template <class T>
void expect_accounting(const SpscRing<T>& ring, std::uint64_t attempts) {
  EXPECT_EQ(ring.pushed() + ring.dropped_newest(), attempts);
  EXPECT_EQ(ring.popped() + ring.dropped() + ring.size_approx(), attempts);
  EXPECT_EQ(ring.dropped(), ring.dropped_oldest() + ring.dropped_newest());
  EXPECT_LE(ring.size_approx(), ring.capacity());
}

std::vector<std::uint64_t> drain(SpscRing<Item>& ring) {
  std::vector<std::uint64_t> out;
  Item it;
  while (ring.pop(it)) out.push_back(number_of(it));
  return out;
}

std::vector<std::uint64_t> iota(std::uint64_t from, std::uint64_t to) {  // [from, to)
  std::vector<std::uint64_t> v;
  for (std::uint64_t i = from; i < to; ++i) v.push_back(i);
  return v;
}

TEST(SpscRing, CapacityMustBeAPowerOfTwo) {
  for (std::size_t bad : {std::size_t{0}, std::size_t{3}, std::size_t{6}, std::size_t{1000}})
    EXPECT_THROW(SpscRing<Item>(bad, OverflowPolicy::DropOldest), std::invalid_argument) << bad;
  EXPECT_THROW(SpscRing<Item>(SpscRing<Item>::kMaxCapacity * 2, OverflowPolicy::DropNewest), std::invalid_argument);
  for (std::size_t good : {std::size_t{1}, std::size_t{2}, std::size_t{1024}}) {
    SpscRing<Item> ring(good, OverflowPolicy::DropNewest);
    EXPECT_EQ(ring.capacity(), good);
    EXPECT_EQ(ring.policy(), OverflowPolicy::DropNewest);
  }
}

TEST(SpscRing, EmptyRingPopsNothingAndLeavesTheOutputAlone) {
  for (auto policy : {OverflowPolicy::DropOldest, OverflowPolicy::DropNewest}) {
    SpscRing<Item> ring(8, policy);
    Item it = make_item(77);
    EXPECT_FALSE(ring.pop(it));
    EXPECT_EQ(number_of(it), 77u);
    EXPECT_EQ(ring.size_approx(), 0u);
    expect_accounting(ring, 0);
    ASSERT_TRUE(ring.push(make_item(0)));
    ASSERT_TRUE(ring.pop(it));
    EXPECT_EQ(number_of(it), 0u);
    EXPECT_FALSE(ring.pop(it));
    EXPECT_EQ(number_of(it), 0u);
    expect_accounting(ring, 1);
  }
}

TEST(SpscRing, FifoAcrossManyWrapsWithoutLoss) {
  for (auto policy : {OverflowPolicy::DropOldest, OverflowPolicy::DropNewest}) {
    SpscRing<Item> ring(4, policy);
    std::uint64_t next_in = 0;
    std::uint64_t next_out = 0;
    for (int round = 0; round < 1000; ++round) {
      const int n = 1 + round % 4;  // 1..4 items: up to exactly full
      for (int i = 0; i < n; ++i) ASSERT_TRUE(ring.push(make_item(next_in++)));
      EXPECT_EQ(ring.size_approx(), static_cast<std::size_t>(n));
      Item it;
      for (int i = 0; i < n; ++i) {
        ASSERT_TRUE(ring.pop(it));
        ASSERT_EQ(number_of(it), next_out++);
      }
      ASSERT_FALSE(ring.pop(it));
    }
    EXPECT_EQ(ring.dropped(), 0u);
    EXPECT_EQ(ring.popped(), next_in);
    expect_accounting(ring, next_in);
  }
}

TEST(SpscRing, DropNewestKeepsTheFirstItemsAndRefusesTheRest) {
  SpscRing<Item> ring(8, OverflowPolicy::DropNewest);
  for (std::uint64_t i = 0; i < 8; ++i) EXPECT_TRUE(ring.push(make_item(i)));
  for (std::uint64_t i = 8; i < 13; ++i) EXPECT_FALSE(ring.push(make_item(i)));
  EXPECT_EQ(ring.size_approx(), 8u);
  EXPECT_EQ(ring.pushed(), 8u);
  EXPECT_EQ(ring.dropped_newest(), 5u);
  EXPECT_EQ(ring.dropped_oldest(), 0u);
  expect_accounting(ring, 13);

  // One slot freed: exactly one more push fits.
  Item it;
  ASSERT_TRUE(ring.pop(it));
  EXPECT_EQ(number_of(it), 0u);
  EXPECT_TRUE(ring.push(make_item(13)));
  EXPECT_FALSE(ring.push(make_item(14)));
  EXPECT_EQ(ring.dropped_newest(), 6u);
  expect_accounting(ring, 15);

  std::vector<std::uint64_t> want = iota(1, 8);
  want.push_back(13);
  EXPECT_EQ(drain(ring), want);
  EXPECT_EQ(ring.popped(), 9u);
  expect_accounting(ring, 15);
}

TEST(SpscRing, DropOldestKeepsTheNewestCapacityItems) {
  SpscRing<Item> ring(8, OverflowPolicy::DropOldest);
  const std::uint64_t n = 8 * 3 + 5;
  for (std::uint64_t i = 0; i < n; ++i) EXPECT_TRUE(ring.push(make_item(i)));
  EXPECT_EQ(ring.pushed(), n);
  EXPECT_EQ(ring.size_approx(), 8u);
  // Counted before the consumer has looked: the overwritten items are known from the indices.
  EXPECT_EQ(ring.dropped_oldest(), n - 8);
  expect_accounting(ring, n);

  EXPECT_EQ(drain(ring), iota(n - 8, n));
  EXPECT_EQ(ring.dropped_oldest(), n - 8);
  EXPECT_EQ(ring.dropped_newest(), 0u);
  EXPECT_EQ(ring.popped(), 8u);
  expect_accounting(ring, n);
}

TEST(SpscRing, DropOldestOverwritesOnlyWhatDoesNotFit) {
  SpscRing<Item> ring(8, OverflowPolicy::DropOldest);
  for (std::uint64_t i = 0; i < 8; ++i) ASSERT_TRUE(ring.push(make_item(i)));
  Item it;
  ASSERT_TRUE(ring.pop(it));
  ASSERT_TRUE(ring.pop(it));
  EXPECT_EQ(number_of(it), 1u);
  // Two free slots; three more items: exactly one unread item (2) is lost.
  for (std::uint64_t i = 8; i < 11; ++i) ASSERT_TRUE(ring.push(make_item(i)));
  EXPECT_EQ(ring.size_approx(), 8u);
  EXPECT_EQ(ring.dropped_oldest(), 1u);
  expect_accounting(ring, 11);
  EXPECT_EQ(drain(ring), iota(3, 11));
  EXPECT_EQ(ring.dropped_oldest(), 1u);
  expect_accounting(ring, 11);

  // The ring keeps working after a lap: no further loss when it does not overflow.
  for (std::uint64_t i = 11; i < 19; ++i) ASSERT_TRUE(ring.push(make_item(i)));
  EXPECT_EQ(drain(ring), iota(11, 19));
  EXPECT_EQ(ring.dropped_oldest(), 1u);
  expect_accounting(ring, 19);
}

TEST(SpscRing, DropOldestLappedManyTimesBetweenPops) {
  SpscRing<Item> ring(4, OverflowPolicy::DropOldest);
  std::uint64_t next = 0;
  std::uint64_t lost = 0;
  for (int round = 0; round < 200; ++round) {
    const std::uint64_t n = static_cast<std::uint64_t>(round % 13);  // 0..12 items, up to 3 laps
    for (std::uint64_t i = 0; i < n; ++i) ASSERT_TRUE(ring.push(make_item(next++)));
    lost += n > 4 ? n - 4 : 0;
    const std::uint64_t kept = n < 4 ? n : 4;
    ASSERT_EQ(drain(ring), iota(next - kept, next)) << "round " << round;
    ASSERT_EQ(ring.dropped_oldest(), lost);
    expect_accounting(ring, next);
  }
}

TEST(SpscRing, CapacityOne) {
  SpscRing<Item> oldest(1, OverflowPolicy::DropOldest);
  SpscRing<Item> newest(1, OverflowPolicy::DropNewest);
  for (std::uint64_t i = 0; i < 5; ++i) {
    EXPECT_TRUE(oldest.push(make_item(i)));
    EXPECT_EQ(newest.push(make_item(i)), i == 0);
  }
  EXPECT_EQ(drain(oldest), std::vector<std::uint64_t>{4});
  EXPECT_EQ(drain(newest), std::vector<std::uint64_t>{0});
  EXPECT_EQ(oldest.dropped_oldest(), 4u);
  EXPECT_EQ(newest.dropped_newest(), 4u);
  expect_accounting(oldest, 5);
  expect_accounting(newest, 5);
}

TEST(SpscRing, ItemsThatAreNotAWholeNumberOfWords) {
  struct Odd {
    unsigned char bytes[13];
  };
  SpscRing<Odd> ring(4, OverflowPolicy::DropOldest);
  for (unsigned char i = 0; i < 6; ++i) {
    Odd o;
    for (unsigned char k = 0; k < 13; ++k) o.bytes[k] = static_cast<unsigned char>(i * 16 + k);
    ASSERT_TRUE(ring.push(o));
  }
  Odd o;
  for (unsigned char i = 2; i < 6; ++i) {
    ASSERT_TRUE(ring.pop(o));
    for (unsigned char k = 0; k < 13; ++k) ASSERT_EQ(o.bytes[k], i * 16 + k);
  }
  EXPECT_FALSE(ring.pop(o));

  // Smaller than a word.
  SpscRing<std::uint16_t> small(2, OverflowPolicy::DropNewest);
  EXPECT_TRUE(small.push(0xBEEF));
  EXPECT_TRUE(small.push(0x1234));
  EXPECT_FALSE(small.push(0x5678));
  std::uint16_t v = 0;
  ASSERT_TRUE(small.pop(v));
  EXPECT_EQ(v, 0xBEEF);
  ASSERT_TRUE(small.pop(v));
  EXPECT_EQ(v, 0x1234);
  EXPECT_FALSE(small.pop(v));
  expect_accounting(small, 3);
}

// Producer: numbers 0..n-1 as fast as it can. Consumer: pops, pausing every `pause_every`
// items (until 2 x capacity more pushes were tried). Monitor: reads the counters meanwhile.
// Checks order, integrity and exact accounting.
void stress(OverflowPolicy policy, std::size_t capacity, std::uint64_t n, std::uint64_t pause_every) {
  SpscRing<Item> ring(capacity, policy);
  std::vector<unsigned char> refused(n, 0);   // written by the producer only
  std::vector<unsigned char> received(n, 0);  // written by the consumer only
  std::atomic<bool> producer_done{false};
  std::atomic<bool> consumer_done{false};

  std::thread producer([&] {
    for (std::uint64_t i = 0; i < n; ++i)
      if (!ring.push(make_item(i))) refused[i] = 1;
    producer_done.store(true, std::memory_order_release);
  });

  std::uint64_t popped = 0;
  std::uint64_t torn = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t gaps = 0;  // numbers skipped between consecutive pops
  std::int64_t last = -1;
  std::thread consumer([&] {
    Item it;
    for (;;) {
      if (!ring.pop(it)) {
        if (!producer_done.load(std::memory_order_acquire)) continue;
        if (!ring.pop(it)) break;  // every push is complete and visible: drained
      }
      const std::uint64_t num = number_of(it);
      if (num >= n) {
        ++torn;
        continue;
      }
      if (static_cast<std::int64_t>(num) <= last) {
        ++out_of_order;
      } else {
        gaps += num - static_cast<std::uint64_t>(last + 1);
        last = static_cast<std::int64_t>(num);
      }
      received[num] = 1;
      ++popped;
      if (popped % pause_every == 0) {
        // Pause until the producer has tried twice the capacity more: the ring overflows
        // whatever the relative speed of the threads (e.g. under ThreadSanitizer).
        const std::uint64_t until = ring.pushed() + ring.dropped_newest() + 2 * capacity;
        while (ring.pushed() + ring.dropped_newest() < until && !producer_done.load(std::memory_order_acquire))
          std::this_thread::yield();
      }
    }
    consumer_done.store(true, std::memory_order_release);
  });

  std::uint64_t monitor_reads = 0;
  std::uint64_t monitor_errors = 0;
  std::thread monitor([&] {
    std::uint64_t last_pushed = 0;
    std::uint64_t last_popped = 0;
    while (!consumer_done.load(std::memory_order_acquire)) {
      // In this order no item can be counted twice (see SpscRing's comments), so the sum never
      // exceeds the attempts read last.
      const std::uint64_t popped_now = ring.popped();
      const std::uint64_t dropped = ring.dropped();
      const std::size_t size = ring.size_approx();
      const std::uint64_t pushed = ring.pushed();
      const std::uint64_t attempts = pushed + ring.dropped_newest();
      if (size > ring.capacity() || pushed < last_pushed || popped_now < last_popped || attempts > n ||
          popped_now + dropped + size > attempts)
        ++monitor_errors;
      last_pushed = pushed;
      last_popped = popped_now;
      ++monitor_reads;
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  });

  producer.join();
  consumer.join();
  monitor.join();

  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(monitor_errors, 0u) << "of " << monitor_reads;
  EXPECT_EQ(popped, ring.popped());
  EXPECT_EQ(ring.size_approx(), 0u);
  expect_accounting(ring, n);
  EXPECT_EQ(popped + ring.dropped(), n);
  // Every number either arrived, or was refused by push, or was overwritten; never two.
  std::uint64_t refused_count = 0;
  std::uint64_t neither = 0;
  for (std::uint64_t i = 0; i < n; ++i) {
    refused_count += refused[i];
    if (refused[i] && received[i]) ADD_FAILURE() << "item " << i << " refused and received";
    neither += !refused[i] && !received[i];
  }
  EXPECT_EQ(refused_count, ring.dropped_newest());
  EXPECT_EQ(neither, ring.dropped_oldest());
  // What the consumer saw missing is exactly what the ring counted as dropped.
  EXPECT_EQ(gaps + (n - 1 - static_cast<std::uint64_t>(last)), ring.dropped());
  if (policy == OverflowPolicy::DropOldest) {
    EXPECT_EQ(ring.dropped_newest(), 0u);
    EXPECT_EQ(last, static_cast<std::int64_t>(n - 1));  // the newest item always survives
  } else {
    EXPECT_EQ(ring.dropped_oldest(), 0u);
    EXPECT_TRUE(received[0]);  // the oldest item always survives
  }
  // The pauses make the consumer fall behind: the test exercised the overflow path.
  EXPECT_GT(ring.dropped(), 0u);
  EXPECT_GT(popped, 0u);
  std::printf("[          ] %s capacity %zu: %llu popped, %llu dropped\n",
              policy == OverflowPolicy::DropOldest ? "DropOldest" : "DropNewest", capacity,
              static_cast<unsigned long long>(popped), static_cast<unsigned long long>(ring.dropped()));
}

constexpr std::uint64_t kStressItems = 1'000'000;

TEST(SpscRingStress, DropOldestTwoThreads) { stress(OverflowPolicy::DropOldest, 256, kStressItems, 4096); }
TEST(SpscRingStress, DropNewestTwoThreads) { stress(OverflowPolicy::DropNewest, 256, kStressItems, 4096); }
// A tiny ring, so the producer keeps overwriting the slot the consumer is copying (torn reads).
TEST(SpscRingStress, DropOldestTinyRingTwoThreads) {
  stress(OverflowPolicy::DropOldest, 4, kStressItems, 1024);
}

}  // namespace
}  // namespace posefair::daemon
