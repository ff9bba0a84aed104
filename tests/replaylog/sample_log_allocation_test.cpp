// SampleLogWriter's promise that append() never allocates, also when it flushes and rotates
// to the next file. This binary replaces the global operator new/delete with counting
// versions, so it must not share an executable with other tests.
#include <unistd.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/drivers/sample_log.hpp"

namespace {
std::atomic<std::size_t> g_allocations{0};
std::atomic<std::ptrdiff_t> g_live_bytes{0};  // requested bytes not yet freed
void* volatile g_sink = nullptr;  // pointers escape here so test allocations cannot be elided

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

namespace posefair::drivers {
namespace {

std::size_t allocations() { return g_allocations.load(std::memory_order_relaxed); }

TEST(SampleLogAllocation, TheCounterSeesAllocations) {
  // Without this the zero below would prove nothing.
  const std::size_t before = allocations();
  auto* v = new std::vector<double>(100);
  g_sink = v;
  delete v;
  std::string s(100, 'x');
  g_sink = s.data();
  EXPECT_GE(allocations() - before, 3u);
}

TEST(SampleLogAllocation, AppendFlushAndRotationNeverAllocate) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("posefair-replaylog-alloc-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    SampleLogHeader header;
    header.streams = {{1, "head", "test"}, {2, "hand", "test"}};
    SampleLogWriterOptions o;
    o.buffer_bytes = 8192;
    o.flush_bytes = 2048;    // flushes every 20 samples from append()
    o.max_file_bytes = 8000; // and a new file every ~75
    o.flush_interval = 0.05;
    o.sync = true;
    SampleLogWriter w(dir / "run.pflog", header, o);

    std::vector<Sample> samples(3000);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      samples[i].stream_id = 1 + static_cast<std::uint32_t>(i % 2);
      samples[i].sequence = i / 2;
      samples[i].time = 0.005 * static_cast<double>(i);
      samples[i].flags = i % 2 == 0 ? kHasPosition : 0u;
    }

    // The measured run: no gtest assertions inside (they may allocate), only bookkeeping.
    bool all_accepted = true;
    bool all_flushed = true;
    const std::size_t before = allocations();
    for (std::size_t i = 0; i < samples.size(); ++i) {
      all_accepted = w.append(samples[i]) && all_accepted;
      if (i % 7 == 0) all_flushed = w.maybe_flush(samples[i].time) && all_flushed;
      if (i == 2000) all_flushed = w.flush() && all_flushed;
    }
    all_flushed = w.flush() && all_flushed;
    const std::size_t during = allocations() - before;

    EXPECT_EQ(during, 0u) << "append()/flush()/maybe_flush() allocated";
    EXPECT_TRUE(all_accepted);
    EXPECT_TRUE(all_flushed);
    EXPECT_GT(w.current_index(), 30u);  // the loop rotated many times
    EXPECT_EQ(w.stats().samples_written, samples.size());
    EXPECT_EQ(w.stats().write_errors, 0u);
    EXPECT_TRUE(w.close());
    EXPECT_EQ(read_sample_log_set(dir / "run.pflog").samples.size(), samples.size());
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace posefair::drivers
