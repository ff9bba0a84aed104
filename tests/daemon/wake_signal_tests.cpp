// WakeSignal (the engine's and publisher's futex event count) and AdaptiveSpin (the bounded spin
// before parking, [daemon] spin_us): no wake is ever lost, whichever wake mode, and the spin's
// budget adapts within its bounds.
#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "posefair/daemon/adaptive_spin.hpp"
#include "posefair/daemon/wake_signal.hpp"

namespace posefair::daemon {
namespace {

using namespace std::chrono_literals;

// Four producers each publish items (an atomic count) and notify; the consumer takes whatever is
// published and otherwise waits. All five threads share one CPU, so a producer is often
// preempted between its increment and its look at the sleeper (the window that loses a wake if
// the wake is taken by the wrong notifier). A lost wake leaves the consumer asleep with items
// published: the test then fails instead of hanging, and releases it.
void expect_no_lost_wake(bool batched, std::chrono::microseconds spin) {
  constexpr int kProducers = 4;
  constexpr std::uint64_t kPerProducer = 20'000;
  WakeSignal signal(batched);
  AdaptiveSpin spinner(spin);
  std::atomic<std::uint64_t> published{0}, taken{0};
  std::atomic<bool> done{false}, give_up{false};
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(0, &one);
  const auto pin = [&one] { ::sched_setaffinity(0, sizeof one, &one); };
  std::thread consumer([&] {
    pin();
    while (!give_up.load()) {
      const std::uint32_t seen = signal.prepare();
      const std::uint64_t now = published.load(std::memory_order_acquire);
      if (now > taken.load(std::memory_order_relaxed)) {
        taken.store(now, std::memory_order_relaxed);
        continue;
      }
      if (now == kProducers * kPerProducer) break;
      signal.wait(seen, spinner);
    }
    done.store(true);
  });
  std::vector<std::thread> producers;
  for (int p = 0; p < kProducers; ++p)
    producers.emplace_back([&] {
      pin();
      for (std::uint64_t i = 0; i < kPerProducer; ++i) {
        published.fetch_add(1, std::memory_order_release);
        signal.notify();
        if (i % 64 == 0) std::this_thread::yield();
      }
    });
  for (auto& t : producers) t.join();
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!done.load() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(1ms);
  const bool finished = done.load();
  give_up.store(true);
  signal.notify();  // releases a consumer that lost its wake, so the test can end
  consumer.join();
  EXPECT_TRUE(finished) << "the consumer slept with " << published.load() - taken.load() << " items published: a lost wake";
  EXPECT_EQ(taken.load(), kProducers * kPerProducer);
}

TEST(WakeSignal, PerBatchWakesNeverLoseOne) { expect_no_lost_wake(true, 0us); }
TEST(WakeSignal, PerSampleWakesNeverLoseOne) { expect_no_lost_wake(false, 0us); }
TEST(WakeSignal, SpinningThenParkingNeverLosesAWake) { expect_no_lost_wake(true, 20us); }

TEST(WakeSignal, AWaitAfterANotifyReturnsAtOnce) {
  WakeSignal signal;
  const std::uint32_t seen = signal.prepare();
  signal.notify();
  const auto t0 = std::chrono::steady_clock::now();
  signal.wait(seen);  // would sleep for ever if the notify were missed
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s);
}

TEST(AdaptiveSpin, ZeroBoundNeverSpins) {
  AdaptiveSpin spin;
  EXPECT_FALSE(spin.enabled());
  int looks = 0;
  EXPECT_FALSE(spin.spin([&] { return ++looks > 0; }));
  EXPECT_EQ(looks, 0);
}

TEST(AdaptiveSpin, TheBudgetHalvesWhenNothingComesAndGrowsBackWhenWorkDoes) {
  AdaptiveSpin spin(std::chrono::microseconds(64));
  EXPECT_EQ(spin.budget_ns(), 64'000u);
  EXPECT_FALSE(spin.spin([] { return false; }));
  EXPECT_EQ(spin.budget_ns(), 32'000u);
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(spin.spin([] { return false; }));
  EXPECT_EQ(spin.budget_ns(), 4'000u) << "the floor is 1/16 of the bound";
  EXPECT_TRUE(spin.spin([] { return true; }));
  EXPECT_EQ(spin.budget_ns(), 8'000u);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(spin.spin([] { return true; }));
  EXPECT_EQ(spin.budget_ns(), 64'000u) << "the bound caps it";
}

TEST(AdaptiveSpin, ASpinThatFindsWorkLaterStillReturnsTrue) {
  AdaptiveSpin spin(std::chrono::milliseconds(50));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(spin.spin([&] { return std::chrono::steady_clock::now() - t0 > 1ms; }));
  EXPECT_EQ(spin.budget_ns(), 50'000'000u);
}

}  // namespace
}  // namespace posefair::daemon
