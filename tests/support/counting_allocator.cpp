// Counting replacements of every replaceable global operator new/delete, and the counters
// declared in counting_allocator.hpp.
//
// Any binary that links this file has its global new/delete replaced by these, for every test
// and every library in it: such a binary must hold only allocation tests.
#include "counting_allocator.hpp"

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>

namespace {

std::atomic<std::size_t> g_allocations{0};
std::atomic<std::ptrdiff_t> g_live_bytes{0};  // requested bytes not yet freed
void* volatile g_sink = nullptr;  // pointers escape here so test allocations cannot be elided

// Plain thread_locals, constant-initialised: reaching them from operator new runs no
// initialiser and never allocates.
constinit thread_local std::size_t t_allocations = 0;
constinit thread_local std::atomic<std::size_t>* t_slot = nullptr;
constinit thread_local std::atomic<std::size_t>* t_suspended_slot = nullptr;

// Static storage: a slot outlives the thread that counts into it.
std::array<std::atomic<std::size_t>, posefair::testing::kCounterSlots> g_slots{};
std::atomic<int> g_slots_claimed{0};  // may run past kCounterSlots: failed claims

// Each block carries its requested size in a header in front of it (kHeader bytes, or the
// alignment for over-aligned blocks) so that the unsized deletes can account for it too.
constexpr std::size_t kHeader = alignof(std::max_align_t);

void* counted_alloc(std::size_t size, std::size_t align) {
  const std::size_t header = align > kHeader ? align : kHeader;
  const std::size_t total = (size + header + header - 1) / header * header;  // aligned_alloc wants a multiple
  auto* base = static_cast<unsigned char*>(align > kHeader ? std::aligned_alloc(align, total) : std::malloc(total));
  if (base == nullptr) return nullptr;
  std::memcpy(base, &size, sizeof size);
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  g_live_bytes.fetch_add(static_cast<std::ptrdiff_t>(size), std::memory_order_relaxed);
  ++t_allocations;
  if (std::atomic<std::size_t>* slot = t_slot) slot->fetch_add(1, std::memory_order_relaxed);
  return base + header;
}

// Out of line, so that GCC does not see free() applied to what operator new returned once the
// replacement deletes are inlined (-Wmismatched-new-delete cannot tell they belong together).
[[gnu::noinline]] void counted_free(void* p, std::size_t align) noexcept {
  if (p == nullptr) return;
  const std::size_t header = align > kHeader ? align : kHeader;
  unsigned char* base = static_cast<unsigned char*>(p) - header;
  std::size_t size = 0;
  std::memcpy(&size, base, sizeof size);
  g_live_bytes.fetch_sub(static_cast<std::ptrdiff_t>(size), std::memory_order_relaxed);
  std::free(base);
}

void* alloc_or_throw(std::size_t size, std::size_t align) {
  if (void* p = counted_alloc(size, align)) return p;
  throw std::bad_alloc();
}

}  // namespace

// Every replaceable allocation function.
void* operator new(std::size_t size) { return alloc_or_throw(size, 0); }
void* operator new[](std::size_t size) { return alloc_or_throw(size, 0); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return counted_alloc(size, 0); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return counted_alloc(size, 0); }
void* operator new(std::size_t size, std::align_val_t al) { return alloc_or_throw(size, static_cast<std::size_t>(al)); }
void* operator new[](std::size_t size, std::align_val_t al) { return alloc_or_throw(size, static_cast<std::size_t>(al)); }
void* operator new(std::size_t size, std::align_val_t al, const std::nothrow_t&) noexcept {
  return counted_alloc(size, static_cast<std::size_t>(al));
}
void* operator new[](std::size_t size, std::align_val_t al, const std::nothrow_t&) noexcept {
  return counted_alloc(size, static_cast<std::size_t>(al));
}
void operator delete(void* p) noexcept { counted_free(p, 0); }
void operator delete[](void* p) noexcept { counted_free(p, 0); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p, 0); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p, 0); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_free(p, 0); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_free(p, 0); }
void operator delete(void* p, std::align_val_t al) noexcept { counted_free(p, static_cast<std::size_t>(al)); }
void operator delete[](void* p, std::align_val_t al) noexcept { counted_free(p, static_cast<std::size_t>(al)); }
void operator delete(void* p, std::size_t, std::align_val_t al) noexcept { counted_free(p, static_cast<std::size_t>(al)); }
void operator delete[](void* p, std::size_t, std::align_val_t al) noexcept { counted_free(p, static_cast<std::size_t>(al)); }
void operator delete(void* p, std::align_val_t al, const std::nothrow_t&) noexcept {
  counted_free(p, static_cast<std::size_t>(al));
}
void operator delete[](void* p, std::align_val_t al, const std::nothrow_t&) noexcept {
  counted_free(p, static_cast<std::size_t>(al));
}

namespace posefair::testing {

std::size_t allocations() { return g_allocations.load(std::memory_order_relaxed); }
std::ptrdiff_t live_bytes() { return g_live_bytes.load(std::memory_order_relaxed); }
std::size_t thread_allocations() { return t_allocations; }
void keep(void* p) { g_sink = p; }

int claim_counter_slot() {
  const int slot = g_slots_claimed.fetch_add(1, std::memory_order_relaxed);
  if (slot >= kCounterSlots) return -1;
  t_slot = &g_slots[static_cast<std::size_t>(slot)];
  return slot;
}

void suspend_counter_slot() {
  if (t_slot) t_suspended_slot = t_slot;
  t_slot = nullptr;
}

void resume_counter_slot() {
  if (t_suspended_slot) t_slot = t_suspended_slot;
  t_suspended_slot = nullptr;
}

bool has_counter_slot() { return t_slot != nullptr || t_suspended_slot != nullptr; }

int counter_slots_claimed() {
  const int n = g_slots_claimed.load(std::memory_order_relaxed);
  return n < kCounterSlots ? n : kCounterSlots;
}

std::size_t slot_allocations(int slot) {
  if (slot < 0 || slot >= counter_slots_claimed()) return 0;
  return g_slots[static_cast<std::size_t>(slot)].load(std::memory_order_relaxed);
}

void release_counter_slots() {
  t_slot = nullptr;
  t_suspended_slot = nullptr;
  for (std::atomic<std::size_t>& s : g_slots) s.store(0, std::memory_order_relaxed);
  g_slots_claimed.store(0, std::memory_order_relaxed);
}

}  // namespace posefair::testing
