// SampleLogWriter's promise that append() never allocates, also when it flushes and rotates
// to the next file. This binary links tests/support/counting_allocator.cpp, which replaces the
// global operator new/delete with counting versions, so it must not share an executable with
// other tests.
#include <unistd.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/formats/sample_log.hpp"

#include "../support/counting_allocator.hpp"

namespace posefair::formats {
namespace {

using testing::allocations;
using testing::keep;

TEST(SampleLogAllocation, TheCounterSeesAllocations) {
  // Without this the zero below would prove nothing.
  const std::size_t before = allocations();
  auto* v = new std::vector<double>(100);
  keep(v);
  delete v;
  std::string s(100, 'x');
  keep(s.data());
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
}  // namespace posefair::formats
