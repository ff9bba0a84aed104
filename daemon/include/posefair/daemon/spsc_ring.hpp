#pragma once
// SpscRing<T>: the daemon's lock-free ring between exactly one producer thread and exactly one
// consumer thread, with an overflow policy (overflow_policy.hpp) and exact loss counters.
//
// - Fixed capacity, a power of two, all memory allocated by the constructor. push() and pop()
//   never allocate, never block, never make a system call; both are wait-free except that
//   pop() loops once per overwrite it discovers (bounded: each turn moves the read index on).
// - DropNewest: push() returns false while the ring is full and counts the item in
//   dropped_newest(). The ring keeps the oldest items.
// - DropOldest: push() always succeeds and never waits for or even looks at the consumer;
//   when the ring is full it overwrites the oldest unread item. The ring keeps the newest
//   `capacity()` items; the consumer notices each overwrite and counts it in dropped_oldest().
//
// Why not boost::lockfree::spsc_queue: its producer can only fail when the queue is full; it
// cannot discard the oldest element, because only the consumer may move the read index.
// Overwriting from the producer side means the consumer can be reading a slot while the
// producer rewrites it, which needs the seqlock scheme below.
//
// How DropOldest stays correct (the producer never waits, every item is counted once):
// - Item number i (0, 1, 2, ...) lives in slot i % capacity. Every slot carries a sequence
//   word: 2i+1 while item i is being written, 2i+2 once it is complete. A slot's sequence
//   only grows, so it tells the consumer exactly which item the slot holds.
// - The payload is stored as std::atomic<std::uint64_t> words (release stores, acquire
//   loads), so a read racing an overwrite is no data race in C++ terms and ThreadSanitizer
//   models every access (no standalone fences, which it does not understand).
// - pop() for item r reads the sequence (s1), the words, and the sequence again (s2).
//   s1 < 2r+2: item r is not complete yet, the ring is empty. s1 == s2 == 2r+2: the copy is
//   item r, untorn (if any word had come from a later write, the acquire load of that word
//   would make the writer's earlier "2j+1" store visible to the s2 load). Otherwise item r is
//   gone (overwritten before or during the read): the consumer counts it as dropped and moves
//   on, to r+1 or straight to head-capacity, the oldest item that can still be intact
//   (the slot of every item below it has been claimed by a later push: the head is published
//   after a push's "2j+1" and words, before its "2j+2").
// - Each item number is thus classified exactly once by the consumer (popped or dropped);
//   items the consumer has not looked at yet are either still in the ring or already
//   overwritten, which dropped_oldest() infers from the indices (head - tail - capacity). At
//   quiescence, pushed() + dropped_newest() == popped() + dropped() + size_approx() exactly.
// DropNewest uses the same slots: the producer reads the consumer's index (cached, re-read only
// when the ring looks full) and never overwrites an unread slot, so the consumer never laps.
//
// Counters and size_approx() may be read from any thread. While both ends run, each is a
// recent value (they are separate atomics, read one after the other), but no item is ever
// counted twice: popped() + dropped() + size_approx() <= pushed() + dropped_newest() when read
// in that order. Once both ends are quiet (e.g. after joining them) all are exact.
//
// T must be trivially copyable (items are copied as bytes). posefair::Sample and FairedPose
// are NOT (Eigen's fixed-size types declare copy constructors): carry flattened records
// (ring_items.hpp) instead.
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "posefair/daemon/overflow_policy.hpp"

namespace posefair::daemon {

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing<T> copies items as bytes: T must be trivially copyable");
  static_assert(!std::is_const_v<T> && !std::is_volatile_v<T> && !std::is_reference_v<T>);
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free);

 public:
  static constexpr std::size_t kMaxCapacity = std::size_t{1} << 32;

  // capacity: a power of two in [1, kMaxCapacity]; throws std::invalid_argument otherwise.
  SpscRing(std::size_t capacity, OverflowPolicy policy)
      : slots_(make_slots(capacity)), capacity_(capacity), mask_(capacity - 1), policy_(policy) {}

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer thread only. DropOldest: always stores, returns true. DropNewest: false (and the
  // item counted in dropped_newest()) when the ring is full.
  bool push(const T& item) noexcept {
    const std::uint64_t h = head_.load(std::memory_order_relaxed);  // written only here
    if (policy_ == OverflowPolicy::DropNewest && h - tail_cache_ >= capacity_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (h - tail_cache_ >= capacity_) {
        dropped_newest_.store(dropped_newest_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        return false;
      }
    }
    Slot& slot = slots_[h & mask_];
    // Release on every store keeps the order odd sequence -> words -> head -> even sequence
    // (plain moves on x86-64). The head goes before the item is complete so that a consumer
    // (or reader of the counters) never sees the tail ahead of the head. Word by word straight
    // from the item: no staging buffer, whose wide copy would stall store-to-load forwarding.
    slot.seq.store(2 * h + 1, std::memory_order_release);
    const auto* src = reinterpret_cast<const unsigned char*>(&item);
    for (std::size_t k = 0; k < kFullWords; ++k) {
      std::uint64_t w;
      std::memcpy(&w, src + 8 * k, 8);
      slot.words[k].store(w, std::memory_order_release);
    }
    if constexpr (kFullWords < kWords) {  // a last partial word
      std::uint64_t w = 0;
      std::memcpy(&w, src + 8 * kFullWords, sizeof(T) - 8 * kFullWords);
      slot.words[kFullWords].store(w, std::memory_order_release);
    }
    head_.store(h + 1, std::memory_order_release);
    slot.seq.store(2 * h + 2, std::memory_order_release);
    return true;
  }

  // Consumer thread only. The oldest item still in the ring, or false when empty. Under
  // DropOldest, items overwritten since the last pop are skipped and counted here.
  // After false, `out` is unchanged unless this call caught the producer overwriting the item
  // it was copying (DropOldest only): then it holds that discarded, torn copy. Treat it as
  // unspecified.
  bool pop(T& out) noexcept {
    std::uint64_t r = tail_.load(std::memory_order_relaxed);  // written only here
    std::uint64_t skipped = 0;
    for (;;) {
      Slot& slot = slots_[r & mask_];
      const std::uint64_t complete = 2 * r + 2;
      const std::uint64_t s1 = slot.seq.load(std::memory_order_acquire);
      if (s1 < complete) {  // item r not (fully) written yet
        if (skipped != 0) publish_consumer(r, false, skipped);
        return false;
      }
      if (s1 == complete) {
        // Straight into `out` (see the comment on pop) and checked afterwards.
        auto* dst = reinterpret_cast<unsigned char*>(&out);
        for (std::size_t k = 0; k < kFullWords; ++k) {
          const std::uint64_t w = slot.words[k].load(std::memory_order_acquire);
          std::memcpy(dst + 8 * k, &w, 8);
        }
        if constexpr (kFullWords < kWords) {
          const std::uint64_t w = slot.words[kFullWords].load(std::memory_order_acquire);
          std::memcpy(dst + 8 * kFullWords, &w, sizeof(T) - 8 * kFullWords);
        }
        if (slot.seq.load(std::memory_order_relaxed) == complete) {
          publish_consumer(r + 1, true, skipped);
          return true;
        }
      }
      // Item r was overwritten (s1 shows a later item, or s2 changed during the copy). Items
      // below head - capacity are certainly lost too (the pushes into their slots have begun:
      // each stored its odd sequence before the head we read); item head - capacity may still
      // be intact.
      const std::uint64_t h = head_.load(std::memory_order_acquire);
      std::uint64_t next = r + 1;
      if (h > capacity_ && h - capacity_ > next) next = h - capacity_;
      skipped += next - r;
      r = next;
    }
  }

  std::size_t capacity() const noexcept { return static_cast<std::size_t>(capacity_); }
  OverflowPolicy policy() const noexcept { return policy_; }

  // Items a drain would return now (at most capacity()). Any thread; exact when quiet.
  std::size_t size_approx() const noexcept {
    const std::uint64_t t = tail_.load(std::memory_order_acquire);
    const std::uint64_t h = head_.load(std::memory_order_acquire);
    if (h <= t) return 0;
    return static_cast<std::size_t>(h - t < capacity_ ? h - t : capacity_);
  }

  // push() calls that stored their item (all of them under DropOldest). Any thread.
  std::uint64_t pushed() const noexcept { return head_.load(std::memory_order_acquire); }
  // pop() calls that returned an item. Any thread.
  std::uint64_t popped() const noexcept { return popped_.load(std::memory_order_acquire); }
  // Items lost because the ring was full: overwritten unread (DropOldest; including overwrites
  // the consumer has not reached yet) ...
  std::uint64_t dropped_oldest() const noexcept {
    if (policy_ == OverflowPolicy::DropNewest) return 0;
    // skipped_ first: it is stored after tail_, so no item is counted both as skipped and as
    // beyond the tail (a reader racing the consumer may undercount for a moment, never over).
    const std::uint64_t s = skipped_.load(std::memory_order_acquire);
    const std::uint64_t t = tail_.load(std::memory_order_acquire);
    const std::uint64_t h = head_.load(std::memory_order_acquire);
    return s + (h > t + capacity_ ? h - t - capacity_ : 0);
  }
  // ... or refused by push() (DropNewest).
  std::uint64_t dropped_newest() const noexcept { return dropped_newest_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const noexcept { return dropped_oldest() + dropped_newest(); }

 private:
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;
  static constexpr std::size_t kFullWords = sizeof(T) / 8;

  struct alignas(64) Slot {
    std::atomic<std::uint64_t> seq{0};  // 2i+1: item i being written; 2i+2: item i complete
    std::atomic<std::uint64_t> words[kWords];
  };

  // The consumer's state after a pop: the tail first, then the counters (release), so a
  // reader that sees a counter's new value also sees the tail that goes with it.
  void publish_consumer(std::uint64_t tail, bool popped_one, std::uint64_t skipped) noexcept {
    tail_.store(tail, std::memory_order_release);
    if (popped_one) popped_.store(popped_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
    if (skipped != 0) skipped_.store(skipped_.load(std::memory_order_relaxed) + skipped, std::memory_order_release);
  }

  static std::unique_ptr<Slot[]> make_slots(std::size_t capacity) {
    if (capacity == 0 || capacity > kMaxCapacity || !std::has_single_bit(capacity))
      throw std::invalid_argument("SpscRing: capacity must be a power of two in [1, 2^32]");
    return std::unique_ptr<Slot[]>(new Slot[capacity]());
  }

  // Set at construction, read-only afterwards.
  const std::unique_ptr<Slot[]> slots_;
  const std::uint64_t capacity_;
  const std::uint64_t mask_;
  const OverflowPolicy policy_;

  // Producer's line.
  alignas(64) std::atomic<std::uint64_t> head_{0};  // items stored so far = next item number
  std::uint64_t tail_cache_ = 0;                    // DropNewest: the consumer's tail, last seen
  std::atomic<std::uint64_t> dropped_newest_{0};

  // Consumer's line.
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // next item number to read
  std::atomic<std::uint64_t> popped_{0};
  std::atomic<std::uint64_t> skipped_{0};  // overwrites the consumer has stepped over
};

}  // namespace posefair::daemon
