// daemon::Pipeline's promise that the engine thread and the publisher thread do not allocate
// (docs/operations.md), counted over whole runs: each of the two threads claims a counter slot
// of the counting allocator in PipelineHooks::on_realtime_thread_start, the first thing it
// does, and the test reads the slots after stop() has joined the threads (the slots are static
// storage, so they outlive the threads). A JSON-lines output, which allocates a string per pose
// on the publisher thread, shows that the slots do see those threads' allocations. Sending to
// subscribers of the subscription port (a table another thread keeps changing) is counted too.
//
// This binary links tests/support/counting_allocator.cpp, which replaces the global operator
// new/delete: it must hold only allocation tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <utility>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "posefair/daemon/config.hpp"
#include "posefair/daemon/fusion_stage.hpp"
#include "posefair/daemon/pipeline.hpp"
#include "posefair/daemon/ring_items.hpp"
#include "posefair/daemon/subscriber_table.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/formats/sample_log.hpp"

#include "../support/counting_allocator.hpp"
#include "../support/gyro_tracker_motion.hpp"
#include "../support/test_files.hpp"
#include "../support/udp_collector.hpp"

namespace posefair::daemon {
namespace {

namespace counting = posefair::testing;
using namespace std::chrono_literals;
using testing::UdpCollector;
using testing::wait_until;

const std::filesystem::path kDemoCsv = std::filesystem::path(POSEFAIR_SOURCE_DIR) / "data/demo/broad-07-excerpt.csv";
constexpr std::uint64_t kDemoSamples = 2000;
constexpr std::uint32_t kSession = 0x5eed0a11u;

// One stream (id 1) with the given driver table body and engine keys, and one output to
// 127.0.0.1:port with the given encoding.
std::string config_text(std::uint16_t port, const std::string& driver, const std::string& solver,
                        const std::string& encoding, const std::string& daemon_keys) {
  return "[daemon]\nsession_id = " + std::to_string(kSession) + "\n" + daemon_keys +
         "\n"
         "[[stream]]\n"
         "id = 1\n"
         "name = \"alloc\"\n"
         "ring_capacity = 4096\n"
         "[stream.driver]\n" +
         driver +
         "[stream.engine]\n"
         "solver = \"" +
         solver +
         "\"\n"
         "order = 3\n"
         "window = 32\n" +
         std::string(solver == "gauss-newton" ? "smoothing = 100\n" : "") +
         "lag = 4\n"
         "\n"
         "[[output]]\n"
         "encoding = \"" +
         encoding +
         "\"\n"
         "destinations = [\"127.0.0.1:" +
         std::to_string(port) + "\"]\n";
}

std::string replay_driver() { return "type = \"replay\"\npath = \"" + kDemoCsv.string() + "\"\ntiming = \"fast\"\n"; }

struct PipelineRun {
  bool ended = false;                     // the source ended on its own
  int threads = 0;                        // real-time threads that claimed a counter slot
  int expected_threads = 0;               // the engine, the publisher unless the engine publishes, the drivers that faired
  std::vector<std::size_t> allocations;   // per claimed slot, over the whole run
  StreamStats stats;
  std::uint64_t datagrams = 0;
};

// Runs the pipeline of config_text(port) until its sources end, stops it (which joins the
// engine and publisher threads) and reads what each real-time thread allocated.
PipelineRun run_config(const std::function<std::string(std::uint16_t port)>& config_text,
                       std::shared_ptr<SubscriberTable> subscribers = nullptr) {
  PipelineRun run;
  UdpCollector receiver;  // the output's destination; its thread claims no counter slot
  const DaemonConfig config = parse_config(config_text(receiver.port()), "/virtual/pipeline-alloc.toml");
  const bool drivers_fair = config.daemon.fair_on == FairThread::Driver;
  // The engine thread, and the publisher's unless the engine publishes; with fair_on = "driver"
  // also each driver thread that took the engine role (counted while it held it).
  const int base_threads = config.daemon.publish_on == PublishThread::Engine ? 1 : 2;
  static std::atomic<int> fairing_drivers{0};
  fairing_drivers.store(0);
  PipelineHooks hooks;
  // Stateless, so calling it allocates nothing; claiming a slot does not allocate either.
  hooks.on_realtime_thread_start = [] { counting::claim_counter_slot(); };
  hooks.on_engine_role = [](bool held) {
    if (!held) {
      counting::suspend_counter_slot();
    } else if (counting::has_counter_slot()) {
      counting::resume_counter_slot();
    } else {
      counting::claim_counter_slot();
      fairing_drivers.fetch_add(1);
    }
  };
  {
    Pipeline pipeline(config, kSession, {}, false, hooks, subscribers);
    pipeline.start();
    run.ended = wait_until([&] { return pipeline.sources_ended(); }, 30s);
    pipeline.stop();
    const std::vector<StreamStats> stats = pipeline.stats();
    if (!stats.empty()) run.stats = stats.front();
  }
  run.threads = counting::counter_slots_claimed();
  run.expected_threads = base_threads + fairing_drivers.load();
  // With fair_on = "driver" a driver thread faired (or the slots would not see the fairing).
  if (drivers_fair && fairing_drivers.load() == 0) run.expected_threads = -1;
  for (int i = 0; i < run.threads; ++i) run.allocations.push_back(counting::slot_allocations(i));
  receiver.drain(100ms, 5s);
  run.datagrams = receiver.datagrams();
  return run;
}

// One stream (config_text above) to one output.
PipelineRun run_pipeline(const std::string& driver, const std::string& solver, const std::string& encoding,
                         std::shared_ptr<SubscriberTable> subscribers = nullptr, const std::string& daemon_keys = "") {
  return run_config([&](std::uint16_t port) { return config_text(port, driver, solver, encoding, daemon_keys); },
                    std::move(subscribers));
}

// Writes samples (stream 1) to a sample log at path; the replay driver's table body for it.
std::string replay_of(const std::filesystem::path& path, const std::vector<Sample>& samples,
                      const std::string& timing = "timing = \"fast\"\n") {
  formats::SampleLogHeader h;
  h.streams = {{1, "imu", "test"}};
  formats::SampleLogWriterOptions o;
  o.sync = false;
  formats::SampleLogWriter w(path, h, o);
  for (const Sample& s : samples) w.append(s);
  return "type = \"replay\"\npath = \"" + path.string() + "\"\n" + timing;
}

std::string describe(const PipelineRun& run) {
  std::ostringstream s;
  s << "slots:";
  for (std::size_t a : run.allocations) s << ' ' << a;
  s << "; received " << run.stats.received << ", emitted " << run.stats.emitted << ", published " << run.stats.published
    << ", datagrams " << run.datagrams;
  return s.str();
}

class PipelineAllocation : public ::testing::Test {
 protected:
  // The threads of any previous run have been joined: the slots are free to reuse.
  void SetUp() override { counting::release_counter_slots(); }
};

// The slots themselves: a thread's allocations are counted in its slot, and only its own.
TEST_F(PipelineAllocation, ASlotCountsItsThreadsAllocationsOnly) {
  std::atomic<int> slot{-2};
  std::thread t([&slot] {
    slot.store(counting::claim_counter_slot());
    for (int i = 0; i < 3; ++i) {
      auto* p = new int(i);
      counting::keep(p);
      delete p;
    }
  });
  t.join();
  auto* mine = new std::vector<double>(10);  // the main thread has no slot
  counting::keep(mine);
  delete mine;
  ASSERT_EQ(slot.load(), 0);
  EXPECT_EQ(counting::counter_slots_claimed(), 1);
  EXPECT_EQ(counting::slot_allocations(0), 3u);
  EXPECT_GT(counting::thread_allocations(), 0u);
}

TEST_F(PipelineAllocation, ReplayToABinaryOutputAllocatesNothingOnTheRealtimeThreads) {
  const PipelineRun run = run_pipeline(replay_driver(), "linear", "binary");
  std::printf("%s\n", describe(run).c_str());
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended) << "the replay did not end";
  ASSERT_EQ(run.threads, run.expected_threads) << "the engine and the publisher thread each claim a slot";
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.received, kDemoSamples);
  EXPECT_EQ(run.stats.published, kDemoSamples);
  EXPECT_EQ(run.stats.send_failures, 0u);
  EXPECT_GT(run.datagrams, 0u);
}

// Each way of handing over ([daemon] fair_on, publish_on, spin_us, wake; docs/config.md) allocates
// nothing either: the spin, the batched wake and publishing from the engine thread are all
// plain loads, stores and system calls.
TEST_F(PipelineAllocation, EveryHandOverOptionAllocatesNothingOnTheRealtimeThreads) {
  for (const char* keys : {"publish_on = \"engine\"\nspin_us = 100\n", "publish_on = \"publisher\"\nspin_us = 100\n",
                           "publish_on = \"publisher\"\nwake = \"per-sample\"\n", "fair_on = \"engine\"\n",
                           "fair_on = \"driver\"\npublish_on = \"publisher\"\n"}) {
    SCOPED_TRACE(keys);
    counting::release_counter_slots();
    const PipelineRun run = run_pipeline(replay_driver(), "linear", "binary", nullptr, keys);
    SCOPED_TRACE(describe(run));
    EXPECT_TRUE(run.ended);
    ASSERT_EQ(run.threads, run.expected_threads);
    for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
    EXPECT_EQ(run.stats.published, kDemoSamples);
  }
}

// A raw IMU stream (every other sample raw-only, the rest orientations with their readings):
// the engine's raw-only path, which counts and skips, allocates nothing either.
TEST_F(PipelineAllocation, RawOnlySamplesAllocateNothingOnTheRealtimeThreads) {
  testing::ScratchDir dir;
  std::vector<Sample> samples(1000);
  for (std::uint64_t i = 0; i < samples.size(); ++i) {
    Sample& s = samples[i];
    s.stream_id = 1;
    s.sequence = i;
    s.time = 0.005 * static_cast<double>(i);
    s.flags = (i % 2 ? kNoOrientation : 0u) | kHasGyro | kHasAccel;
    s.gyro = Vec3(0, 0, 0.5);
    s.accel = Vec3(0, 0, 9.81);
  }
  const PipelineRun run = run_pipeline(replay_of(dir / "raw.pflog", samples), "linear", "binary");
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended);
  ASSERT_EQ(run.threads, run.expected_threads);
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.received, 1000u);
  EXPECT_EQ(run.stats.raw_unfused, 500u);
  EXPECT_EQ(run.stats.published, 500u);
}

// Orientations that carry a gyroscope reading: gyro-aided fairing, with its bias and time
// offset estimates, on the engine thread, allocates nothing either.
TEST_F(PipelineAllocation, GyroAidedFairingAllocatesNothingOnTheRealtimeThreads) {
  posefair::testing::ScratchDir dir;
  posefair::testing::GyroTrackerSpec spec;
  spec.seconds = 5.0;
  spec.offset = 0.004;
  spec.bias = Vec3(0.01, 0.0, -0.02);
  const PipelineRun run = run_pipeline(
      replay_of(dir / "gyro.pflog", posefair::testing::make_gyro_tracker_stream(spec).samples), "linear", "binary");
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended);
  ASSERT_EQ(run.threads, run.expected_threads);
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.received, 1000u);
  EXPECT_EQ(run.stats.published, 1000u);
  EXPECT_TRUE(run.stats.engine.gyro.active);
  EXPECT_GT(run.stats.engine.gyro.intervals, 900u);
}

// An orientation stream faired with the gyroscope of another stream ([stream.engine]
// gyro_stream): the IMU's readings kept for the pairing and matched to each sample, on the
// engine thread, allocate nothing either. Replayed in real time (4x), the IMU's readings
// beginning 0.1 s after the tracker's samples so that they lead them, and are matched.
TEST_F(PipelineAllocation, AGyroFromAnotherStreamAllocatesNothingOnTheRealtimeThreads) {
  posefair::testing::ScratchDir dir;
  posefair::testing::GyroTrackerSpec optical;
  optical.rate_hz = 120.0;
  optical.seconds = 2.0;
  std::vector<Sample> tracker = posefair::testing::make_gyro_tracker_stream(optical).samples;
  for (Sample& x : tracker) x.flags &= ~static_cast<std::uint32_t>(kHasGyro);
  posefair::testing::GyroTrackerSpec imu;
  imu.rate_hz = 1000.0;
  imu.start_time = 0.1;
  imu.seconds = optical.seconds - imu.start_time;
  imu.offset = 0.003;
  const std::string real_time = "speed = 4.0\n";
  const std::string tracker_driver = replay_of(dir / "optical.pflog", tracker, real_time);
  const std::string imu_driver = replay_of(dir / "imu.pflog", posefair::testing::make_imu_readings(imu), real_time);
  const PipelineRun run = run_config([&](std::uint16_t port) {
    return "[[stream]]\nid = 1\nname = \"optical\"\nring_capacity = 4096\n[stream.driver]\n" + tracker_driver +
           "[stream.engine]\ngyro_stream = \"imu\"\n[[stream]]\nid = 2\nname = \"imu\"\nring_capacity = 4096\n"
           "[stream.driver]\n" + imu_driver + "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(port) + "\"]\n";
  });
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended);
  ASSERT_EQ(run.threads, run.expected_threads);
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.published, tracker.size());
  ASSERT_TRUE(run.stats.gyro_pairing);
  EXPECT_GT(run.stats.gyro_pairing->matched, tracker.size() / 2);
  EXPECT_GT(run.stats.engine.gyro.intervals, 0u);
}

TEST_F(PipelineAllocation, GaussNewtonOnASyntheticStreamAllocatesNothingOnTheRealtimeThreads) {
  const PipelineRun run =
      run_pipeline("type = \"synthetic\"\nrate_hz = 2000.0\nduration = 0.5\n", "gauss-newton", "binary");
  std::printf("%s\n", describe(run).c_str());
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended) << "the synthetic stream did not end";
  ASSERT_EQ(run.threads, run.expected_threads) << "the engine and the publisher thread each claim a slot";
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.received, 1000u);  // 0.5 s at 2000 Hz
  EXPECT_EQ(run.stats.published, run.stats.received);
  EXPECT_EQ(run.stats.send_failures, 0u);
  EXPECT_GT(run.datagrams, 0u);
}

// Gap bridging and resampling run on the engine thread too: the demo recording with three
// 20-sample dropouts, bridged and published at 1 kHz, allocates nothing.
TEST_F(PipelineAllocation, BridgingAndResamplingAllocateNothingOnTheRealtimeThreads) {
  testing::ScratchDir dir("posefair-alloc-");
  const std::string text = testing::slurp(kDemoCsv);
  std::istringstream in(text);
  std::string line, csv;
  for (std::size_t row = 0; std::getline(in, line); ++row)
    if (row == 0 || (row - 1) % 500 < 480) csv += line + "\n";  // rows 480..499 of every 500 lost
  std::ofstream(dir / "gaps.csv") << csv;
  const PipelineRun run = run_pipeline("type = \"replay\"\npath = \"" + (dir / "gaps.csv").string() +
                                           "\"\ntiming = \"fast\"\n"
                                           "[stream.spline]\npublish_rate_hz = 1000.0\nbridge_gap = 0.1\n",
                                       "linear", "binary");
  std::printf("%s\n", describe(run).c_str());
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended) << "the replay did not end";
  ASSERT_EQ(run.threads, run.expected_threads) << "the engine and the publisher thread each claim a slot";
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.received, kDemoSamples - 80);
  EXPECT_EQ(run.stats.bridged_gaps, 3u) << "the fourth dropout is the recording's end";
  EXPECT_TRUE(run.stats.resampling);
  EXPECT_GT(run.stats.resampled, 6900u);  // 7 s at 1 kHz, less the spline's delay at both ends
  // As fast as possible, 3.5 grid poses per sample outrun the publisher: the oldest are dropped,
  // and counted.
  EXPECT_EQ(run.stats.published + run.stats.publish_dropped, run.stats.resampled);
}

// pose_interpolation = "matrix-lerp" with positions (the demo has them): one logarithm per
// interval, an exponential per pose, and the separate fallback for a step of pi/2 or more (the
// first sample after the first dropout is turned by half a turn), all without allocating.
TEST_F(PipelineAllocation, MatrixLerpBridgingAndResamplingAllocateNothingOnTheRealtimeThreads) {
  testing::ScratchDir dir("posefair-alloc-");
  const std::string text = testing::slurp(kDemoCsv);
  std::istringstream in(text);
  std::string line, csv;
  for (std::size_t row = 0; std::getline(in, line); ++row) {
    if (row != 0 && (row - 1) % 500 >= 480) continue;  // rows 480..499 of every 500 lost
    if (row == 501) {
      // t,qw,qx,qy,qz,...: q times (0,1,0,0), a half turn about x, is (-qx, qw, qz, -qy).
      std::vector<std::string> f;
      std::stringstream fields(line);
      for (std::string v; std::getline(fields, v, ',');) f.push_back(v);
      auto negated = [](const std::string& v) { return v[0] == '-' ? v.substr(1) : "-" + v; };
      const std::string w = f[1], x = f[2], y = f[3], z = f[4];
      f[1] = negated(x);
      f[2] = w;
      f[3] = z;
      f[4] = negated(y);
      line.clear();
      for (std::size_t i = 0; i < f.size(); ++i) line += (i ? "," : "") + f[i];
    }
    csv += line + "\n";
  }
  std::ofstream(dir / "gaps.csv") << csv;
  const PipelineRun run = run_pipeline("type = \"replay\"\npath = \"" + (dir / "gaps.csv").string() +
                                           "\"\ntiming = \"fast\"\n"
                                           "[stream.spline]\npublish_rate_hz = 1000.0\nbridge_gap = 0.1\n"
                                           "pose_interpolation = \"matrix-lerp\"\n",
                                       "linear", "binary");
  std::printf("%s; lerp fallbacks %llu\n", describe(run).c_str(), static_cast<unsigned long long>(run.stats.lerp_fallbacks));
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended) << "the replay did not end";
  ASSERT_EQ(run.threads, run.expected_threads) << "the engine and the publisher thread each claim a slot";
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_EQ(run.stats.bridged_gaps, 3u);
  EXPECT_TRUE(run.stats.matrix_lerp);
  EXPECT_GE(run.stats.lerp_fallbacks, 1u) << "the half turn after the first dropout";
  EXPECT_GT(run.stats.resampled, 6900u);
}

// The negative control: JSON lines allocate a string per pose on the publisher thread, so the
// slots do count those threads' allocations. Which slot is which thread is not known: one of
// them (the publisher's) allocated, the other (the engine's) still did not.
// [stream.fusion]: the stage runs on the engine thread, so an estimator update must not
// allocate. The stage is driven here directly, on this thread, so that every estimator and
// the bad input it counts (NaN, a gap, a stuck magnetometer) are covered; the whole pipeline
// with a fusion stage: pipeline_tests' RawSamplesWithAFusionStage...
TEST_F(PipelineAllocation, TheFusionStageAllocatesNothingPerSample) {
  for (const char* estimator : {"vqf", "madgwick", "mahony"}) {
    SCOPED_TRACE(estimator);
    FusionStage stage(FusionConfig{estimator, {}});
    std::vector<Sample> samples(4000);
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const double t = 0.005 * static_cast<double>(k);
      Sample& s = samples[k];
      s.time = k >= 2000 ? t + 1.0 : t;  // one gap of a second
      s.gyro = Vec3(std::sin(t), 0.5 * std::cos(t), 0.2);
      s.accel = Vec3(0.3 * std::sin(t), 0.2, 9.8);
      s.mag = k >= 3000 && k < 3400 ? Vec3(1.0, 20.0, -40.0) : Vec3(std::cos(t), 20.0, -40.0);  // stuck for 2 s
      if (k % 97 == 0) s.gyro.y() = std::nan("");
      s.flags = kHasGyro | kHasAccel | kHasMag | kNoOrientation;
    }
    Sample first = samples[0];
    stage.apply(first);  // any lazy set-up happens here, outside the count
    const std::size_t before = counting::thread_allocations();
    for (std::size_t k = 1; k < samples.size(); ++k) {
      Sample s = samples[k];
      stage.apply(s);
    }
    EXPECT_EQ(counting::thread_allocations() - before, 0u);
    EXPECT_GT(stage.state().nonfinite, 0u);
    EXPECT_GT(stage.state().mag_stuck, 0u);
    EXPECT_EQ(stage.state().gaps, 1u);
    EXPECT_EQ(stage.state().bad_time_steps, 0u);
  }
}

TEST_F(PipelineAllocation, AJsonOutputAllocatesOnThePublisherThreadOnly) {
  // A publisher thread of its own, so that its allocations and the engine's are told apart.
  const PipelineRun run = run_pipeline(replay_driver(), "linear", "json", nullptr, "publish_on = \"publisher\"\n");
  std::printf("%s\n", describe(run).c_str());
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended) << "the replay did not end";
  ASSERT_EQ(run.threads, run.expected_threads) << "the engine and the publisher thread each claim a slot";
  EXPECT_GT(*std::max_element(run.allocations.begin(), run.allocations.end()), 0u)
      << "the publisher's JSON strings were not counted";
  EXPECT_EQ(*std::min_element(run.allocations.begin(), run.allocations.end()), 0u) << "the engine thread allocated";
  EXPECT_EQ(run.stats.published, kDemoSamples);
  EXPECT_EQ(run.stats.send_failures, 0u);
  EXPECT_GT(run.datagrams, 0u);
}

}  // namespace
}  // namespace posefair::daemon

namespace posefair::daemon {
namespace {

// Subscribers (the subscription port's table) are sent to from the publisher thread too: with
// one subscriber whose entry another thread keeps renewing, so the publisher copies the table
// again and again, the real-time threads still allocate nothing.
TEST_F(PipelineAllocation, SendingToSubscribersAllocatesNothingOnTheRealtimeThreads) {
  UdpCollector subscriber;
  auto table = std::make_shared<SubscriberTable>(8, 8);
  Subscriber s;
  s.address = *Endpoint::parse("127.0.0.1:" + std::to_string(subscriber.port()));
  s.expires_ns = static_cast<std::int64_t>(monotonic_ns()) + 60'000'000'000;
  s.last_request_id = 1;
  ASSERT_EQ(table->subscribe(s), SubscriberTable::Outcome::Added);
  std::atomic<bool> stop{false};
  std::atomic<std::uint32_t> renewals{0};
  std::thread renewing([&] {
    Subscriber again = s;
    while (!stop.load()) {
      again.last_request_id = 2 + renewals.fetch_add(1);
      table->subscribe(again);
      std::this_thread::sleep_for(200us);
    }
  });
  const PipelineRun run = run_pipeline(replay_driver(), "linear", "binary", table);
  stop = true;
  renewing.join();
  subscriber.drain(100ms, 5s);
  std::printf("%s; renewals %u, subscriber datagrams %zu\n", describe(run).c_str(), renewals.load(), subscriber.datagrams());
  SCOPED_TRACE(describe(run));
  EXPECT_TRUE(run.ended);
  ASSERT_EQ(run.threads, run.expected_threads);
  for (std::size_t a : run.allocations) EXPECT_EQ(a, 0u) << "a real-time thread allocated";
  EXPECT_GT(renewals.load(), 10u);
  EXPECT_EQ(run.stats.send_failures, 0u);
  EXPECT_EQ(table->list().at(0).sent, kDemoSamples);
  EXPECT_EQ(subscriber.datagrams(), kDemoSamples);
}

}  // namespace
}  // namespace posefair::daemon
