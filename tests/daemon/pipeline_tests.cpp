// daemon::Pipeline in process: configs parsed from TOML text (daemon::parse_config), the demo
// recording replayed as fast as possible into a deliberately slow engine (PipelineHooks), and a
// UDP socket of the test's own on 127.0.0.1 as the only destination. Checks that every sample
// handed over is accounted for exactly once (dropped by the ring, emitted, rejected or out of
// order), that every emitted pose is published and arrives, and that each overflow policy keeps
// the samples it promises to keep.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>

#include <algorithm>
#include <cerrno>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "posefair/core/orientation_error.hpp"
#include "posefair/daemon/client_frames.hpp"
#include "posefair/daemon/config.hpp"
#include "posefair/daemon/pipeline.hpp"
#include "posefair/daemon/status_report.hpp"
#include "posefair/daemon/udp_socket.hpp"
#include "posefair/daemon/wire_protocol.hpp"
#include "posefair/formats/pose_file.hpp"
#include "posefair/formats/sample_log.hpp"
#include "../support/gyro_tracker_motion.hpp"
#include "../support/test_files.hpp"
#include "../support/udp_collector.hpp"

namespace posefair::daemon {
namespace {

using namespace std::chrono_literals;
using testing::ScratchDir;
using testing::UdpCollector;
using testing::wait_until;

const std::filesystem::path kDemoCsv = std::filesystem::path(POSEFAIR_SOURCE_DIR) / "data/demo/broad-07-excerpt.csv";
constexpr std::size_t kDemoSamples = 2000;
constexpr std::uint32_t kSession = 0x5eed0001u;

// One replayed stream (id 1, the demo CSV, by default as fast as possible) to 127.0.0.1:port.
std::string replay_config(std::uint16_t port, std::uint32_t ring_capacity, const std::string& overflow,
                          const std::string& timing = "timing = \"fast\"\n") {
  return "[daemon]\nsession_id = " + std::to_string(kSession) +
         "\n\n"
         "[[stream]]\n"
         "id = 1\n"
         "name = \"broad07\"\n"
         "ring_capacity = " +
         std::to_string(ring_capacity) +
         "\n"
         "overflow = \"" +
         overflow +
         "\"\n"
         "[stream.driver]\n"
         "type = \"replay\"\n"
         "path = \"" +
         kDemoCsv.string() +
         "\"\n" +
         timing +
         "[stream.engine]\n"
         "order = 3\n"
         "window = 16\n"
         "lag = 0\n"
         "\n"
         "[[output]]\n"
         "destinations = [\"127.0.0.1:" +
         std::to_string(port) + "\"]\n";
}

std::vector<double> demo_times() {
  const formats::PoseFile f = formats::read_pose_file(kDemoCsv, {});
  return f.poses().time;
}

// A sample log of one stream (id 1, "imu") holding `samples`.
void write_imu_log(const std::filesystem::path& path, const std::vector<Sample>& samples) {
  formats::SampleLogHeader h;
  h.streams = {{1, "imu", "test"}};
  formats::SampleLogWriterOptions o;
  o.sync = false;
  formats::SampleLogWriter w(path, h, o);
  for (const Sample& s : samples) ASSERT_TRUE(w.append(s));
}

// Runs a one-stream pipeline until its source ends; that stream's counters.
StreamStats run_to_end(const DaemonConfig& config) {
  Pipeline pipeline(config, kSession, {}, false, {});
  pipeline.start();
  EXPECT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s)) << "the source did not end";
  pipeline.stop();
  return pipeline.stats().at(0);
}

struct SlowRun {
  StreamStats stats;
  std::uint64_t hook_calls = 0;
  std::vector<PoseMessage> received;
  std::size_t malformed = 0;
};

// The engine thread as the slow consumer the next tests need: with the default fair_on =
// "driver" a slow fairing would slow the replay's own thread instead, and the ring never fills.
std::string engine_thread_fairs(std::string config) {
  const std::string daemon = "[daemon]\n";
  config.insert(config.find(daemon) + daemon.size(), "fair_on = \"engine\"\n");
  return config;
}

// Replays the demo recording into a ring of 8 with an engine that sleeps ~200 µs before every
// sample, then stops the pipeline and collects what arrived.
SlowRun run_slow_consumer(const std::string& overflow) {
  SlowRun run;
  UdpCollector receiver;
  const DaemonConfig config = parse_config(engine_thread_fairs(replay_config(receiver.port(), 8, overflow)), "/virtual/slow.toml");
  std::atomic<std::uint64_t> calls{0};
  PipelineHooks hooks;
  hooks.before_engine_sample = [&calls](std::uint32_t stream_id) {
    EXPECT_EQ(stream_id, 1u);
    calls.fetch_add(1);
    std::this_thread::sleep_for(200us);
  };
  {
    Pipeline pipeline(config, kSession, {}, false, hooks);
    EXPECT_TRUE(pipeline.warnings().empty());
    pipeline.start();
    EXPECT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s)) << "the replay did not end";
    pipeline.stop();
    const std::vector<StreamStats> stats = pipeline.stats();
    EXPECT_EQ(stats.size(), 1u);
    if (!stats.empty()) run.stats = stats.front();
    EXPECT_EQ(pipeline.next_sequences().at(1), run.stats.published);
  }
  run.hook_calls = calls.load();
  receiver.drain();
  run.received = receiver.messages();
  run.malformed = receiver.malformed();
  return run;
}

// The checks both overflow policies share; returns the sample times that were published.
std::set<double> check_accounting(const SlowRun& run) {
  const StreamStats& s = run.stats;
  SCOPED_TRACE("received " + std::to_string(s.received) + ", ring_dropped " + std::to_string(s.ring_dropped) +
               ", emitted " + std::to_string(s.emitted) + ", rejected " + std::to_string(s.rejected) +
               ", out_of_order " + std::to_string(s.out_of_order) + ", publish_dropped " +
               std::to_string(s.publish_dropped) + ", published " + std::to_string(s.published) +
               ", send_failures " + std::to_string(s.send_failures) + ", datagrams " +
               std::to_string(run.received.size()));
  std::printf("received %llu, ring_dropped %llu, emitted %llu, rejected %llu, out_of_order %llu, published %llu, "
              "publish_dropped %llu, datagrams %zu\n",
              static_cast<unsigned long long>(s.received), static_cast<unsigned long long>(s.ring_dropped),
              static_cast<unsigned long long>(s.emitted), static_cast<unsigned long long>(s.rejected),
              static_cast<unsigned long long>(s.out_of_order), static_cast<unsigned long long>(s.published),
              static_cast<unsigned long long>(s.publish_dropped), run.received.size());
  EXPECT_EQ(s.id, 1u);
  EXPECT_FALSE(s.driver_running);
  EXPECT_EQ(s.received, kDemoSamples);
  EXPECT_GT(s.ring_dropped, 0u) << "a ring of 8 in front of a 200 us/sample engine must overflow";
  EXPECT_LT(s.ring_dropped, s.received);
  // Every sample handed over is counted exactly once.
  EXPECT_EQ(s.received, s.ring_dropped + s.emitted + s.rejected + s.out_of_order);
  // The engine looked at exactly the samples the ring did not drop.
  EXPECT_EQ(run.hook_calls, s.received - s.ring_dropped);
  // The demo recording is clean: nothing the engine saw is refused.
  EXPECT_EQ(s.rejected, 0u);
  // Every emitted pose was either published or counted as lost in the publisher's ring, and
  // every send worked (one destination, loopback). Whether any is lost there: check_publishing.
  EXPECT_EQ(s.published + s.publish_dropped, s.emitted);
  EXPECT_EQ(s.send_failures, 0u);

  // What arrived: exactly `published` datagrams, sequence numbers 0 .. published-1 once each
  // (so a mismatch says whether the daemon or the kernel lost one).
  EXPECT_EQ(run.malformed, 0u);
  EXPECT_EQ(run.received.size(), s.published);
  std::set<std::uint64_t> seqs;
  std::set<double> times;
  for (const PoseMessage& m : run.received) {
    EXPECT_EQ(m.session, kSession);
    EXPECT_EQ(m.stream, 1u);
    EXPECT_TRUE(seqs.insert(m.sequence).second) << "duplicate sequence " << m.sequence;
    EXPECT_LT(m.sequence, s.published);
    EXPECT_TRUE(m.position.has_value()) << "the demo recording has positions";
    times.insert(m.sample_time);
  }
  std::vector<std::uint64_t> missing;
  for (std::uint64_t q = 0; q < s.published && missing.size() < 20; ++q)
    if (!seqs.count(q)) missing.push_back(q);
  EXPECT_TRUE(missing.empty()) << "sequence numbers sent but not received, e.g. " << (missing.empty() ? 0 : missing[0]);
  // Every pose is one of the recording's samples, each at most once.
  EXPECT_EQ(times.size(), run.received.size());
  const std::vector<double> all = demo_times();
  for (double t : times) EXPECT_TRUE(std::binary_search(all.begin(), all.end(), t)) << "unknown sample time " << t;
  return times;
}

// Every emitted pose was published: none lost between the engine and the publisher.
void check_publishing(const SlowRun& run) {
  EXPECT_EQ(run.stats.publish_dropped, 0u);
  EXPECT_EQ(run.stats.published, run.stats.emitted);
  EXPECT_EQ(run.received.size(), run.stats.emitted);
}

// The recording itself goes through the pipeline whole when nothing is in the way: the
// baseline the slow-consumer tests below deviate from.
TEST(Pipeline, ReplayWithALargeRingLosesNothing) {
  UdpCollector receiver;
  const DaemonConfig config = parse_config(replay_config(receiver.port(), 4096, "drop-oldest"), "/virtual/big.toml");
  const StreamStats s = run_to_end(config);
  EXPECT_EQ(s.received, kDemoSamples);
  EXPECT_EQ(s.ring_dropped, 0u);
  EXPECT_EQ(s.emitted, kDemoSamples);
  EXPECT_EQ(s.rejected + s.out_of_order, 0u);
  EXPECT_EQ(s.published, kDemoSamples);
  EXPECT_EQ(s.publish_dropped, 0u);
  receiver.drain();
  const std::vector<PoseMessage> got = receiver.messages();
  ASSERT_EQ(got.size(), kDemoSamples);
  const std::vector<double> times = demo_times();
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].sequence, i);
    ASSERT_EQ(got[i].sample_time, times[i]) << i;
  }
}

TEST(Pipeline, SlowConsumerDropOldestCountsEveryDropAndKeepsTheNewest) {
  const SlowRun run = run_slow_consumer("drop-oldest");
  const std::set<double> sent = check_accounting(run);
  ASSERT_FALSE(HasFailure());
  // The ring holds the newest 8 when the replay ends, and nothing overwrites them after: the
  // last 8 samples of the recording are all among the poses sent.
  const std::vector<double> all = demo_times();
  for (std::size_t i = all.size() - 8; i < all.size(); ++i)
    EXPECT_TRUE(sent.count(all[i])) << "sample " << i << " (t " << all[i] << ") of the newest was not sent";
  // And the survivors are mostly late ones: the very first samples were overwritten unless
  // the engine took them at once.
  EXPECT_FALSE(sent.count(all[all.size() / 2]) && sent.count(all[all.size() / 2 + 1]) &&
               sent.count(all[all.size() / 2 + 2]) && sent.count(all[all.size() / 2 + 3]))
      << "four consecutive samples from the middle survived a ring of 8 in front of a slow engine";
  check_publishing(run);
}

TEST(Pipeline, SlowConsumerDropNewestCountsEveryDropAndKeepsTheOldest) {
  const SlowRun run = run_slow_consumer("drop-newest");
  const std::set<double> sent = check_accounting(run);
  ASSERT_FALSE(HasFailure());
  const std::vector<double> all = demo_times();
  // The very last sample only gets in if the ring happened to have room at that moment; the
  // newest 8 all surviving would mean nothing was refused at the end.
  std::size_t newest_sent = 0;
  for (std::size_t i = all.size() - 8; i < all.size(); ++i) newest_sent += sent.count(all[i]);
  EXPECT_LT(newest_sent, 8u) << "drop-newest kept every one of the newest 8 samples";

  check_publishing(run);
  // The ring refuses new samples while full and starts empty: the first 8 samples of the
  // recording always get in, are faired and sent (the publisher-wake bug loses exactly these
  // oldest poses when one engine pass emits more than 8).
  for (std::size_t i = 0; i < 8; ++i)
    EXPECT_TRUE(sent.count(all[i])) << "sample " << i << " (t " << all[i] << ") of the oldest was not sent";
}

// An engine that is busy for whole passes of its loop: the replay delivers a sample every
// 100 us (the demo recording at 35 times its speed) into a ring of 8, and the engine takes
// ~200 us per sample, so its input ring is never empty and every pass fairs a full budget of
// samples (64) before it looks at anything else. The publisher and the network are idle
// meanwhile: no emitted pose may be lost on its way to them.
TEST(Pipeline, EveryPoseOfALongEnginePassIsPublished) {
  UdpCollector receiver;
  const DaemonConfig config = parse_config(
      engine_thread_fairs(replay_config(receiver.port(), 8, "drop-oldest", "timing = \"original\"\nspeed = 35.0\n")),
      "/virtual/pass.toml");
  PipelineHooks hooks;
  hooks.before_engine_sample = [](std::uint32_t) { std::this_thread::sleep_for(200us); };
  StreamStats s;
  {
    Pipeline pipeline(config, kSession, {}, false, hooks);
    pipeline.start();
    ASSERT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s));
    pipeline.stop();
    s = pipeline.stats().at(0);
  }
  receiver.drain();
  std::printf("received %llu, ring_dropped %llu, emitted %llu, publish_dropped %llu, published %llu, datagrams %zu\n",
              static_cast<unsigned long long>(s.received), static_cast<unsigned long long>(s.ring_dropped),
              static_cast<unsigned long long>(s.emitted), static_cast<unsigned long long>(s.publish_dropped),
              static_cast<unsigned long long>(s.published), receiver.messages().size());
  EXPECT_EQ(s.received, kDemoSamples);
  EXPECT_EQ(s.received, s.ring_dropped + s.emitted + s.rejected + s.out_of_order);
  EXPECT_GT(s.ring_dropped, 0u) << "the scenario needs an engine slower than the replay";
  EXPECT_GT(s.emitted, 128u) << "the scenario needs several full engine passes";
  EXPECT_EQ(s.publish_dropped, 0u);
  EXPECT_EQ(s.published, s.emitted);
  EXPECT_EQ(receiver.messages().size(), s.emitted);
}

}  // namespace
}  // namespace posefair::daemon

namespace posefair::daemon {
namespace {

// Two outputs of one stream: binary with angular velocity and JSON lines without. Both get every
// pose with the same sequence numbers and bit-identical values (JSON numbers round-trip), and
// the rate is 2 log(q_prev⁻¹ q)/dt of the poses actually sent. A third output that lists only
// stream 2 gets stream 2 alone.
TEST(Pipeline, BinaryAndJsonOutputsCarryTheSamePosesAndOutputsHonourTheirStreams) {
  UdpCollector binary, json, only_two;
  std::string text = replay_config(binary.port(), 4096, "drop-oldest");
  text += "angular_velocity = true\n";
  text += "\n[[output]]\nencoding = \"json\"\ndestinations = [\"127.0.0.1:" + std::to_string(json.port()) + "\"]\n";
  text += "\n[[output]]\nstreams = [2]\ndestinations = [\"127.0.0.1:" + std::to_string(only_two.port()) + "\"]\n";
  text += "\n[[stream]]\nid = 2\nname = \"synthetic\"\n[stream.driver]\ntype = \"synthetic\"\nrate_hz = 1000.0\nduration = 0.2\n";
  const DaemonConfig config = parse_config(text, "/virtual/outputs.toml");
  {
    Pipeline pipeline(config, kSession, {}, false, {});
    pipeline.start();
    ASSERT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s));
    pipeline.stop();
  }
  binary.drain();
  json.drain();
  only_two.drain();
  auto of_stream = [](const std::vector<PoseMessage>& all, std::uint32_t id) {
    std::vector<PoseMessage> out;
    for (const PoseMessage& m : all)
      if (m.stream == id) out.push_back(m);
    return out;
  };
  const auto b = of_stream(binary.messages(), 1);
  const auto j = of_stream(json.messages(), 1);
  ASSERT_EQ(b.size(), kDemoSamples);
  ASSERT_EQ(j.size(), kDemoSamples);
  EXPECT_EQ(binary.malformed() + json.malformed(), 0u);
  for (std::size_t i = 0; i < b.size(); ++i) {
    ASSERT_EQ(b[i].sequence, i);
    ASSERT_EQ(j[i].sequence, i);
    EXPECT_EQ(b[i].orientation.coeffs(), j[i].orientation.coeffs()) << i;
    ASSERT_TRUE(b[i].position && j[i].position);
    EXPECT_EQ(*b[i].position, *j[i].position) << i;
    EXPECT_FALSE(j[i].angular_velocity) << "the JSON output did not ask for the rate";
    if (i == 0) {
      EXPECT_FALSE(b[i].angular_velocity) << "no rate before a second pose";
      continue;
    }
    ASSERT_TRUE(b[i].angular_velocity) << i;
    const Vec3 expected = 2.0 * so3::log(b[i - 1].orientation.conjugate() * b[i].orientation) /
                          (b[i].sample_time - b[i - 1].sample_time);
    EXPECT_LT((*b[i].angular_velocity - expected).norm(), 1e-9 * (1.0 + expected.norm())) << i;
  }
  // The output for stream 2 only.
  const auto two = only_two.messages();
  ASSERT_FALSE(two.empty());
  for (const PoseMessage& m : two) ASSERT_EQ(m.stream, 2u);
  EXPECT_EQ(two.size(), of_stream(binary.messages(), 2).size());
}

}  // namespace
}  // namespace posefair::daemon

namespace posefair::daemon {
namespace {

// A multicast output (TTL 0, sent and joined on the loopback interface, so nothing leaves the
// host): a subscriber that joined the group gets every pose.
TEST(Pipeline, MulticastOutputReachesAGroupMember) {
  ReceiveOptions ro;
  ro.group = *Endpoint::parse("239.255.80.72:0");
  ro.interface.name_or_address = "127.0.0.1";
  ro.receive_buffer_bytes = 1 << 20;
  UdpSocket rx = UdpSocket::bind(*Endpoint::parse("0.0.0.0:0"), ro);
  const std::string text = "[[stream]]\nid = 3\nname = \"s\"\n[stream.driver]\ntype = \"synthetic\"\nrate_hz = 1000.0\n"
                           "duration = 0.2\n\n[[output]]\ndestinations = [\"239.255.80.72:" +
                           std::to_string(rx.local_endpoint().port()) + "\"]\nttl = 0\ninterface = \"127.0.0.1\"\n";
  const DaemonConfig config = parse_config(text, "/virtual/multicast.toml");
  ASSERT_EQ(config.outputs.at(0).send.multicast_ttl, 0);
  std::uint64_t published = 0;
  {
    Pipeline pipeline(config, kSession, {}, false, {});
    pipeline.start();
    ASSERT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s));
    pipeline.stop();
    published = pipeline.stats().at(0).published;
    EXPECT_EQ(pipeline.stats().at(0).send_failures, 0u);
  }
  ASSERT_EQ(published, 200u);
  std::vector<std::uint8_t> buffer(kMaxDatagramSize + 1);
  std::uint64_t got = 0;
  while (auto d = rx.receive(buffer, 500ms)) {
    const DecodeResult r = decode_datagram(std::span<const std::uint8_t>(buffer.data(), d->size));
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.message.stream, 3u);
    EXPECT_EQ(r.message.sequence, got);
    ++got;
  }
  EXPECT_EQ(got, published);
}

// A raw IMU stream without a fusion stage: a recording of 300 samples at 100 Hz in which every
// third is raw-only (kNoOrientation: its quaternion a placeholder) and the others are
// orientations, half of them with their gyroscope and accelerometer. The raw-only samples never
// reach the engine: they are counted as raw_unfused (not rejected, not out of order), every
// orientation is faired and published as before, and the recorder keeps all 300 with their
// readings.
TEST(Pipeline, RawOnlySamplesAreCountedNotFairedAndRecordedWithTheirReadings) {
  ScratchDir dir;
  std::vector<Sample> recorded(300);
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    Sample& s = recorded[i];
    s.stream_id = 1;
    s.sequence = i;
    s.time = 10.0 + 0.01 * static_cast<double>(i);
    s.orientation = Quat(Eigen::AngleAxisd(0.01 * static_cast<double>(i), Vec3::UnitZ()));
    if (i % 3 == 2) {
      s.flags = kNoOrientation | kHasGyro | kHasAccel;
      s.orientation = Quat(0, 0, 0, 0);  // what an engine must never see: not even a rotation
    } else if (i % 2 == 0) {
      s.flags = kHasGyro | kHasAccel;
    }
    s.gyro = s.flags ? Vec3(0, 0, 1.0) : Vec3::Zero();
    s.accel = s.flags ? Vec3(0.1, 0, 9.81) : Vec3::Zero();
  }
  write_imu_log(dir / "in.pflog", recorded);
  UdpCollector receiver;
  const std::string text = "[[stream]]\nid = 1\nname = \"imu\"\n[stream.driver]\ntype = \"replay\"\npath = \"" +
                           (dir / "in.pflog").string() +
                           "\"\ntiming = \"fast\"\n[stream.engine]\norder = 3\nwindow = 16\nlag = 0\n\n"
                           "[recorder]\npath = \"" + (dir / "out.pflog").string() + "\"\nsync = false\n\n"
                           "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(receiver.port()) + "\"]\n";
  const DaemonConfig config = parse_config(text, "/virtual/raw.toml");
  const StreamStats s = run_to_end(config);
  EXPECT_EQ(s.received, 300u);
  EXPECT_EQ(s.raw_unfused, 100u);
  EXPECT_EQ(s.rejected + s.out_of_order + s.ring_dropped, 0u);
  EXPECT_EQ(s.emitted, 200u);
  EXPECT_EQ(s.published, 200u);
  receiver.drain();
  const std::vector<PoseMessage> got = receiver.messages();
  ASSERT_EQ(got.size(), 200u);
  for (std::size_t k = 0; k < got.size(); ++k) {
    const std::size_t i = k + k / 2;  // the k-th orientation sample of the recording
    ASSERT_EQ(got[k].sample_time, recorded[i].time) << k;
  }

  const formats::SampleLogContents out = formats::read_sample_log(dir / "out.pflog");
  EXPECT_EQ(s.recorded, 300u);
  ASSERT_EQ(out.samples.size(), 300u);
  for (std::size_t i = 0; i < out.samples.size(); ++i) {
    const Sample& o = out.samples[i];
    EXPECT_EQ(o.flags, recorded[i].flags) << i;
    EXPECT_EQ(o.gyro, recorded[i].gyro) << i;
    EXPECT_EQ(o.accel, recorded[i].accel) << i;
    EXPECT_EQ(o.orientation.coeffs(), recorded[i].orientation.coeffs()) << i;
  }
}

// The recording volume refuses writes (here: RLIMIT_FSIZE, EFBIG; in the soak a full tmpfs,
// ENOSPC) while a 20 kHz source runs: the pipeline reports the error for the main thread to log,
// counts every sample the writer's full buffer refuses as a recorder drop (never as recorded),
// and writes again once the limit is lifted. At the end every sample is recorded or counted as
// dropped, and every recorded one is in the file.
TEST(Pipeline, ARecordingThatCannotBeWrittenCountsItsDropsAndResumes) {
  ScratchDir dir;
  const std::string text = "[[stream]]\nid = 1\nname = \"fast\"\n"
                           "driver = { type = \"synthetic\", rate_hz = 20000.0, duration = 1.0 }\n\n"
                           "[recorder]\npath = \"" + (dir / "out.pflog").string() +
                           "\"\nsync = false\nflush_interval = 0.05\n";
  const DaemonConfig config = parse_config(text, "/virtual/full.toml");
  rlimit original{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &original), 0);
  const auto previous_handler = ::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of the signal
  rlimit small = original;
  small.rlim_cur = 64 * 1024;  // the header and a few hundred records
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  Pipeline pipeline(config, kSession, {}, false, {});
  pipeline.start();
  const bool failed = wait_until([&] { return pipeline.recorder_errno() == EFBIG && pipeline.stats().at(0).record_dropped > 0; }, 10s);
  const StreamStats while_failing = pipeline.stats().at(0);
  ::setrlimit(RLIMIT_FSIZE, &original);
  ::signal(SIGXFSZ, previous_handler);
  ASSERT_TRUE(failed) << "errno " << pipeline.recorder_errno() << ", recorder drops " << while_failing.record_dropped;
  EXPECT_TRUE(wait_until([&] { return pipeline.recorder_errno() == 0; }, 10s)) << "the recording did not resume";
  EXPECT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s));
  pipeline.stop();
  const StreamStats s = pipeline.stats().at(0);
  EXPECT_GT(s.recorded, while_failing.recorded) << "nothing recorded after the limit was lifted";
  EXPECT_EQ(s.received, s.recorded + s.record_dropped);
  const formats::SampleLogContents out = formats::read_sample_log(dir / "out.pflog");
  EXPECT_TRUE(out.stats.problems.empty()) << out.stats.problems.front().message;
  EXPECT_EQ(out.samples.size(), s.recorded);
}

// A raw IMU stream with [stream.fusion]: 20 s at 100 Hz of gyroscope, accelerometer and
// magnetometer readings made from a known rotation (sensor to ENU; gravity up, the field
// pointing north and down), no orientation in any sample. Every sample is fused on the engine
// thread, faired and published; none is counted raw_unfused. The published orientation follows
// the true one: its inclination within 2° throughout, its total error within 3° once the
// heading has converged. The recorder keeps the samples as they came: raw, without the
// estimate.
TEST(Pipeline, RawSamplesWithAFusionStageAreFusedFairedAndPublished) {
  ScratchDir dir;
  constexpr std::size_t kCount = 2000;
  constexpr double kDt = 0.01;
  std::vector<Sample> recorded(kCount);
  std::vector<Quat> truth(kCount);
  Quat q = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()));
  const Vec3 gravity(0, 0, 9.81), field(0, 20.0, -40.0);
  for (std::size_t i = 0; i < kCount; ++i) {
    const double t = kDt * static_cast<double>(i);
    const Vec3 w(0.8 * std::sin(0.7 * t), 0.6 * std::cos(0.5 * t), 0.5);  // rad/s, body frame
    if (i > 0) q = (q * Quat(Eigen::AngleAxisd(w.norm() * kDt, w.normalized()))).normalized();
    truth[i] = q;
    Sample& s = recorded[i];
    s.stream_id = 1;
    s.sequence = i;
    s.time = 5.0 + t;
    s.flags = kNoOrientation | kHasGyro | kHasAccel | kHasMag;
    s.orientation = Quat(0, 0, 0, 0);
    s.gyro = w;
    s.accel = q.conjugate() * gravity;
    s.mag = q.conjugate() * field;
  }
  write_imu_log(dir / "in.pflog", recorded);
  UdpCollector receiver;
  const std::string text = "[[stream]]\nid = 1\nname = \"imu\"\nring_capacity = 4096\n"
                           "[stream.driver]\ntype = \"replay\"\npath = \"" +
                           (dir / "in.pflog").string() +
                           "\"\ntiming = \"fast\"\n[stream.fusion]\nestimator = \"vqf\"\n\n"
                           "[recorder]\npath = \"" + (dir / "out.pflog").string() + "\"\nsync = false\n\n"
                           "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(receiver.port()) + "\"]\n";
  const DaemonConfig config = parse_config(text, "/virtual/fused.toml");
  const StreamStats s = run_to_end(config);
  EXPECT_EQ(s.received, kCount);
  EXPECT_EQ(s.raw_unfused, 0u);
  EXPECT_EQ(s.fusion_waiting, 0u) << "every sample has an accelerometer reading";
  ASSERT_TRUE(s.fusion.has_value());
  EXPECT_EQ(s.fusion->updates, kCount);
  EXPECT_TRUE(s.fusion->initialised);
  EXPECT_FALSE(s.engine.gyro.active) << "a fused orientation is the gyro's already: no gyro aiding unless asked";
  EXPECT_EQ(s.rejected + s.out_of_order + s.ring_dropped, 0u);
  EXPECT_EQ(s.emitted, kCount);
  EXPECT_EQ(s.published, kCount);
  receiver.drain();
  const std::vector<PoseMessage> got = receiver.messages();
  ASSERT_EQ(got.size(), kCount);
  double worst_inclination = 0, worst_late_total = 0;
  for (const PoseMessage& m : got) {
    const auto i = static_cast<std::size_t>(std::lround((m.sample_time - 5.0) / kDt));
    ASSERT_LT(i, kCount);
    const OrientationError e = earth_frame_error(m.orientation, truth[i]);
    worst_inclination = std::max(worst_inclination, e.inclination);
    if (m.sample_time >= 15.0) worst_late_total = std::max(worst_late_total, e.total);
  }
  constexpr double kDeg = M_PI / 180.0;
  EXPECT_LT(worst_inclination, 2.0 * kDeg) << worst_inclination / kDeg << "°";
  EXPECT_LT(worst_late_total, 3.0 * kDeg) << worst_late_total / kDeg << "°";

  const formats::SampleLogContents out = formats::read_sample_log(dir / "out.pflog");
  ASSERT_EQ(out.samples.size(), kCount);
  for (std::size_t i = 0; i < kCount; i += 97) {
    EXPECT_EQ(out.samples[i].flags, recorded[i].flags) << i;
    EXPECT_EQ(out.samples[i].gyro, recorded[i].gyro) << i;
    EXPECT_EQ(out.samples[i].mag, recorded[i].mag) << i;
  }
}

// 200 Hz turning at the constant rate omega (rad/s), read every 15 ms: three samples a read,
// stamped 1 µs apart, the newest of a read 5 ms after it was taken.
std::vector<Sample> clumped_turning_stream(const Vec3& omega) {
  std::vector<Sample> clumped;
  for (int k = 0; k < 800; ++k) {
    Sample s;
    s.stream_id = 1;
    s.sequence = static_cast<std::uint64_t>(k);
    const double sampled = k / 200.0;
    s.orientation = so3::exp(0.5 * sampled * omega);  // half-angle convention
    const double read = std::ceil(sampled / 0.015 + 1e-9) * 0.015;
    s.time = !clumped.empty() && read <= clumped.back().time ? clumped.back().time + 1e-6 : read;
    clumped.push_back(s);
  }
  return clumped;
}

// Receive times of a 200 Hz tracker read every 15 ms: three samples per read, stamped 1 µs
// apart. The published body rate is the rotation over the time the samples were taken apart
// (one interval), not over their stamps' 1 µs, which made it 5000 times too fast.
TEST(Pipeline, TheBodyRateOfSamplesStampedInClumpsIsOverTheirInterval) {
  ScratchDir dir;
  const Vec3 omega(0.3, -0.4, 2.0);  // rad/s, constant: the engine passes the motion unchanged
  const std::vector<Sample> clumped = clumped_turning_stream(omega);
  write_imu_log(dir / "in.pflog", clumped);
  UdpCollector receiver;
  const std::string text = "[[stream]]\nid = 1\nname = \"tracker\"\nring_capacity = 4096\n"
                           "[stream.driver]\ntype = \"replay\"\npath = \"" +
                           (dir / "in.pflog").string() + "\"\ntiming = \"fast\"\n"
                           "\n[[output]]\nangular_velocity = true\ndestinations = [\"127.0.0.1:" + std::to_string(receiver.port()) + "\"]\n";
  const StreamStats st = run_to_end(parse_config(text, "/virtual/clumped.toml"));
  EXPECT_EQ(st.restarts, 0u);
  EXPECT_NEAR(st.engine.rate_hz, 200.0, 3.0);
  receiver.drain();
  const std::vector<PoseMessage> got = receiver.messages();
  ASSERT_EQ(got.size(), clumped.size());
  std::size_t checked = 0;
  for (const PoseMessage& m : got) {
    if (m.sample_time < 1.1) continue;  // a clumped stream's rate is measured over its first second
    ASSERT_TRUE(m.angular_velocity) << m.sequence;
    // The measured rate is the count over the elapsed time: within the 15 ms of a read per second.
    EXPECT_LT((*m.angular_velocity - omega).norm(), 0.02 * omega.norm()) << m.sequence << ": " << m.angular_velocity->transpose();
    ++checked;
  }
  EXPECT_GT(checked, 500u);
}

// A tracker lying still for 6 s at 100 Hz, its noise alternating in sign from sample to sample,
// plus `off(k)` on sample k; and a config replaying it with these [stream.engine] keys.
std::vector<Sample> still_tracker(const std::function<Vec3(int)>& off) {
  std::vector<Sample> still;
  for (int k = 0; k < 600; ++k) {
    Sample s;
    s.stream_id = 1;
    s.sequence = static_cast<std::uint64_t>(k);
    s.time = k / 100.0;
    s.orientation = so3::exp((k % 2 == 0 ? 0.002 : -0.002) * Vec3(1.0, -1.0, 0.5) + off(k));
    still.push_back(s);
  }
  return still;
}
std::string replayed_tracker(const std::filesystem::path& log, const std::string& engine_keys) {
  return "[[stream]]\nid = 1\nname = \"tracker\"\nring_capacity = 4096\n[stream.driver]\ntype = \"replay\"\npath = \"" +
         log.string() + "\"\ntiming = \"fast\"\n[stream.engine]\n" + engine_keys +
         "\n[[output]]\ndestinations = [\"127.0.0.1:9\"]\n";
}

// The still tracker (no random draw decides whether the rest line is straight at the last
// sample: it is): the daemon reports what the engine does at rest, averaged over seconds by
// default and not with rest_memory = 0.
TEST(Pipeline, AStillTrackerIsReportedAtRestAndAveragedOverSeconds) {
  ScratchDir dir;
  const std::vector<Sample> still = still_tracker([](int) { return Vec3::Zero(); });
  write_imu_log(dir / "in.pflog", still);
  for (const std::string memory : {"", "rest_memory = 0\n"}) {
    SCOPED_TRACE(memory.empty() ? "defaults" : memory);
    const StreamStats st = run_to_end(parse_config(replayed_tracker(dir / "in.pflog", memory), "/virtual/still.toml"));
    EXPECT_EQ(st.emitted, still.size());
    EXPECT_TRUE(st.engine.rotation.at_rest);
    EXPECT_EQ(st.engine.rotation.rest_averaged, memory.empty());
  }
}

// A tracker that measures at 50 Hz read at 200 Hz, each measurement four times: the daemon
// reports the repeats carried forward and the source's rate the window runs at; with a lag the
// repeats stay in the window, each a measurement.
TEST(Pipeline, AStreamReadFasterThanItsSourceIsReportedRepeating) {
  ScratchDir dir;
  std::vector<Sample> held;
  for (int k = 0; k < 1200; ++k) {
    Sample s;
    s.stream_id = 1;
    s.sequence = static_cast<std::uint64_t>(k);
    s.time = k / 200.0;
    const int m = k / 4;  // the measurement shown
    s.orientation = so3::exp(Vec3(0.3 * std::sin(m * 0.05), 0.01 * ((m * 7) % 5 - 2) / 2.0, 0.0));
    held.push_back(s);
  }
  write_imu_log(dir / "in.pflog", held);
  for (const std::string keys : {"", "lag = 1\n"}) {
    SCOPED_TRACE(keys.empty() ? "defaults" : keys);
    const StreamStats st = run_to_end(parse_config(replayed_tracker(dir / "in.pflog", keys), "/virtual/held.toml"));
    EXPECT_EQ(st.emitted, held.size());
    if (keys.empty()) {
      EXPECT_TRUE(st.engine.repeating);
      EXPECT_NEAR(st.engine.rate_hz, 50.0, 1.0);
      EXPECT_GT(st.repeated, held.size() / 2);
    } else {
      EXPECT_FALSE(st.engine.repeating);
      EXPECT_NEAR(st.engine.rate_hz, 200.0, 1.0);
      EXPECT_EQ(st.repeated, 0u);
    }
  }
}

// The still tracker with three samples thrown 0.2 rad off: the engine holds each (the outlier
// guard is on by default) and the stats say so; `outlier_threshold = 0` holds none.
TEST(Pipeline, OutliersHeldByTheEngineReachTheStats) {
  ScratchDir dir;
  const std::vector<Sample> still =
      still_tracker([](int k) { return k == 200 || k == 350 || k == 500 ? Vec3(0.2, 0.0, 0.0) : Vec3::Zero(); });
  write_imu_log(dir / "in.pflog", still);
  for (const std::string keys : {"lag = 1\n", "lag = 0\n", "outlier_threshold = 0\n"}) {
    SCOPED_TRACE(keys);
    const StreamStats st = run_to_end(parse_config(replayed_tracker(dir / "in.pflog", keys), "/virtual/outliers.toml"));
    EXPECT_EQ(st.emitted, still.size());
    EXPECT_EQ(st.outliers_held, keys == "outlier_threshold = 0\n" ? 0u : 3u);
    EXPECT_EQ(st.outliers_released, 0u);
  }
}

// A held outlier's pose (with a lag: made at the prediction, not from its measurement) goes out
// flagged `bridged`, as a pose made across a gap does; at lag 0 it goes out as measured, unflagged.
TEST(Pipeline, AHeldPoseIsFlaggedBridgedOnTheWire) {
  ScratchDir dir;
  const std::vector<int> outliers = {200, 350, 500};
  const std::vector<Sample> still = still_tracker([&](int k) {
    return std::find(outliers.begin(), outliers.end(), k) != outliers.end() ? Vec3(0.2, 0.0, 0.0) : Vec3::Zero();
  });
  write_imu_log(dir / "in.pflog", still);
  for (const int lag : {1, 0}) {
    SCOPED_TRACE(::testing::Message() << "lag " << lag);
    UdpCollector receiver;
    const std::string text = "[[stream]]\nid = 1\nname = \"tracker\"\nring_capacity = 4096\n"
                             "[stream.driver]\ntype = \"replay\"\npath = \"" +
                             (dir / "in.pflog").string() + "\"\ntiming = \"fast\"\n[stream.engine]\nlag = " +
                             std::to_string(lag) + "\n[[output]]\ndestinations = [\"127.0.0.1:" +
                             std::to_string(receiver.port()) + "\"]\n";
    run_to_end(parse_config(text, "/virtual/held.toml"));
    receiver.drain();
    std::vector<int> bridged;
    for (const PoseMessage& m : receiver.messages())
      if (m.bridged()) bridged.push_back(static_cast<int>(std::lround(m.sample_time * 100.0)));
    EXPECT_EQ(receiver.messages().size(), still.size());
    EXPECT_EQ(bridged, lag == 0 ? std::vector<int>{} : outliers);
  }
}

// The same receive times: resampled onto a 90 Hz grid, and limited to 100 poses a second. Both
// place the poses at the times the samples were taken (sampled_clock.hpp), not at their stamps:
// through knots 1 µs apart the spline's grid poses were radians off, and by the stamps the limit
// passed only the first, stalest sample of each read, 67 a second.
TEST(Pipeline, SamplesStampedInClumpsAreResampledAndRateLimitedAtTheTimesTheyWereTaken) {
  ScratchDir dir;
  const Vec3 omega(0.3, -0.4, 2.0);
  write_imu_log(dir / "in.pflog", clumped_turning_stream(omega));
  const auto run = [&](const std::string& stream_keys, const std::string& output_keys) {
    UdpCollector receiver;
    const std::string text = "[[stream]]\nid = 1\nname = \"tracker\"\nring_capacity = 4096\n"
                             "[stream.driver]\ntype = \"replay\"\npath = \"" +
                             (dir / "in.pflog").string() + "\"\ntiming = \"fast\"\n" + stream_keys +
                             "\n[[output]]\n" + output_keys + "destinations = [\"127.0.0.1:" +
                             std::to_string(receiver.port()) + "\"]\n";
    run_to_end(parse_config(text, "/virtual/clumped.toml"));
    receiver.drain();
    return receiver.messages();
  };
  {
    SCOPED_TRACE("publish_rate_hz = 90");
    const std::vector<PoseMessage> grid = run("[stream.spline]\npublish_rate_hz = 90\n", "");
    std::size_t checked = 0;
    for (const PoseMessage& m : grid) {
      if (m.sample_time < 1.2) continue;  // the rate is measured over the first second
      // The newest sample of a read is placed at its stamp, 5 ms after it was taken.
      const Quat truth = so3::exp(0.5 * (m.sample_time - 0.005) * omega);
      EXPECT_LT(so3::rotation_angle(m.orientation, truth), 1e-3) << "t = " << m.sample_time;
      ++checked;
    }
    EXPECT_GT(checked, 240u);
  }
  {
    SCOPED_TRACE("max_rate_hz = 100");
    const std::vector<PoseMessage> limited = run("", "max_rate_hz = 100\n");
    std::vector<std::uint64_t> late;
    for (const PoseMessage& m : limited)
      if (m.sample_time >= 1.2) late.push_back(m.sequence);
    // 200 Hz taken, 100 Hz passed: every second sample, 2.8 s of them.
    EXPECT_GT(late.size(), 270u);
    for (std::size_t i = 1; i < late.size(); ++i) EXPECT_EQ(late[i] - late[i - 1], 2u) << "at " << late[i];
  }
}

// A tracker whose samples carry an orientation with 1° of jitter and a gyroscope reading with a
// bias and a 5 ms time offset (20 s at 200 Hz, replayed from a sample log): the engine fairs it
// with the gyro by default, and the bias and offset it estimates reach the stats, the counter
// line and STATUS=. With `gyro_aided = false` the same stream is faired alone, and its error
// against the true motion is at least twice as large.
TEST(Pipeline, OrientationWithAGyroIsFairedWithTheGyroAndItsEstimatesAreReported) {
  ScratchDir dir;
  posefair::testing::GyroTrackerSpec spec;
  spec.seconds = 20.0;
  spec.start_time = 5.0;
  spec.bias = Vec3(0.02, -0.03, 0.01);
  spec.offset = 0.005;
  const posefair::testing::GyroTrackerStream g = posefair::testing::make_gyro_tracker_stream(spec);
  write_imu_log(dir / "in.pflog", g.samples);
  const auto run = [&](const std::string& engine_keys, double& rms_deg) {
    UdpCollector receiver;
    const std::string text = "[[stream]]\nid = 1\nname = \"tracker\"\nring_capacity = 8192\n"
                             "[stream.driver]\ntype = \"replay\"\npath = \"" +
                             (dir / "in.pflog").string() + "\"\ntiming = \"fast\"\n[stream.engine]\n" + engine_keys +
                             "\n[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(receiver.port()) + "\"]\n";
    const StreamStats s = run_to_end(parse_config(text, "/virtual/gyro.toml"));
    EXPECT_EQ(s.emitted, g.samples.size());
    receiver.drain();
    const std::vector<PoseMessage> got = receiver.messages();
    EXPECT_EQ(got.size(), g.samples.size());
    double sum = 0.0;
    std::size_t count = 0;
    for (const PoseMessage& m : got) {
      const auto i = static_cast<std::size_t>(std::lround((m.sample_time - spec.start_time) * spec.rate_hz));
      if (i >= g.truth.size() || m.sample_time < spec.start_time + 2.0) continue;
      const double a = so3::rotation_angle(m.orientation, g.truth[i]);
      sum += a * a;
      ++count;
    }
    rms_deg = count ? std::sqrt(sum / static_cast<double>(count)) * 180.0 / M_PI : 1e9;
    return s;
  };
  double aided = 0.0, alone = 0.0;
  const StreamStats s = run("", aided);
  EXPECT_TRUE(s.engine.gyro.active);
  EXPECT_TRUE(s.engine.gyro.offset_estimated);
  EXPECT_NEAR(s.engine.gyro.time_offset_s, spec.offset, 0.001);
  EXPECT_LT((s.engine.gyro.bias - spec.bias).norm(), 0.005) << s.engine.gyro.bias.transpose();
  const std::vector<std::string> lines = counter_lines({s}, {}, 1.0);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("gyro-aided: bias ("), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("(estimated)"), std::string::npos) << lines[0];
  EXPECT_NE(status_line({s}, {}, 1.0).find(" gyro dt "), std::string::npos) << status_line({s}, {}, 1.0);

  const StreamStats off = run("gyro_aided = false\n", alone);
  EXPECT_FALSE(off.engine.gyro.active);
  EXPECT_EQ(off.engine.gyro.intervals, 0u);
  EXPECT_LT(aided, 0.5 * alone) << "gyro-aided " << aided << "°, alone " << alone << "°";
}

// An optical tracker at 120 Hz with 1° of jitter and no gyroscope, and an IMU on the same body
// at 1 kHz, mounted turned (gyro_mounting) and stamped 4 ms late, replayed as two streams from
// their own sample logs in real time (2x): the optical stream's engine gets the IMU's rate for
// each of its samples ([stream.engine] gyro_stream), finds the time offset, and its error
// against the true motion is far below that of the same optical stream faired alone (a third
// stream). The IMU starts 0.2 s after the tracker, so that in real time its readings lead the
// tracker's samples by 100 ms, as an IMU's do behind an optical system's latency, and a replay
// thread held up that long on a loaded machine (ThreadSanitizer, another test beside it; with
// fair_on = "driver" the tracker's thread passes the IMU's stream first when its role is free) mostly still delivers
// in time: a ThreadSanitizer run with four tests at once left 46 more samples unmatched (3 %), so
// up to 5 % may be. (A later start of the IMU would give more lead, but less time for the offset
// and bias estimates before the error is scored.) The tracker's first 24 samples have no readings
// and are counted unmatched. The counter line and STATUS= name the source.
TEST(Pipeline, AGyroFromAnotherStreamOnTheBodyIsMatchedToEachSampleAndFairsItWithoutLag) {
  ScratchDir dir;
  posefair::testing::GyroTrackerSpec optical;
  optical.rate_hz = 120.0;
  optical.seconds = 12.0;
  optical.jitter_deg = 1.0;
  posefair::testing::GyroTrackerStream tracker = posefair::testing::make_gyro_tracker_stream(optical);
  for (Sample& x : tracker.samples) x.flags &= ~static_cast<std::uint32_t>(kHasGyro);  // an orientation alone
  posefair::testing::GyroTrackerSpec imu;
  imu.rate_hz = 1000.0;
  imu.start_time = 0.2;
  imu.seconds = optical.seconds - imu.start_time;
  imu.offset = 0.004;
  imu.mounting = rotation_from_zyx_degrees(90.0, 0.0, 30.0);
  write_imu_log(dir / "optical.pflog", tracker.samples);
  write_imu_log(dir / "imu.pflog", posefair::testing::make_imu_readings(imu, 0.02));
  UdpCollector receiver;
  const auto stream = [&](int id, const std::string& name, const std::string& log, const std::string& engine) {
    return "[[stream]]\nid = " + std::to_string(id) + "\nname = \"" + name + "\"\nring_capacity = 8192\n[stream.driver]\n"
           "type = \"replay\"\npath = \"" + (dir / log).string() + "\"\nspeed = 2.0\n[stream.engine]\n" + engine;
  };
  const std::string text =
      stream(1, "optical", "optical.pflog", "gyro_stream = \"imu\"\ngyro_mounting = [90.0, 0.0, 30.0]\n") +
      stream(2, "imu", "imu.pflog", "") + stream(3, "optical-alone", "optical.pflog", "") +
      "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(receiver.port()) + "\"]\n";
  std::vector<StreamStats> stats;
  {
    Pipeline pipeline(parse_config(text, "/virtual/paired.toml"), kSession, {}, false, {});
    pipeline.start();
    EXPECT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s)) << "the replays did not end";
    pipeline.stop();
    stats = pipeline.stats();
  }
  ASSERT_EQ(stats.size(), 3u);
  const StreamStats& paired = stats[0];
  const std::size_t n = tracker.samples.size();
  EXPECT_EQ(paired.emitted, n);
  ASSERT_TRUE(paired.gyro_pairing);
  EXPECT_EQ(paired.gyro_pairing->source, "imu");
  EXPECT_EQ(paired.gyro_pairing->matched + paired.gyro_pairing->unmatched, n);
  EXPECT_GE(paired.gyro_pairing->unmatched, 24u) << "the samples before the IMU's first reading";
  EXPECT_GT(paired.gyro_pairing->matched, n - 24 - n / 20) << "the IMU's readings reach nearly every later sample";
  EXPECT_TRUE(paired.engine.gyro.active);
  EXPECT_TRUE(paired.engine.gyro.offset_estimated);
  EXPECT_NEAR(paired.engine.gyro.time_offset_s, imu.offset, 0.001);
  EXPECT_EQ(stats[1].raw_unfused, static_cast<std::uint64_t>(std::lround(imu.seconds * imu.rate_hz)))
      << "the IMU's readings themselves are not faired";
  EXPECT_FALSE(stats[2].gyro_pairing);
  EXPECT_EQ(stats[2].engine.gyro.intervals, 0u);

  receiver.drain();
  std::map<std::uint32_t, std::pair<double, std::size_t>> squared;  // per stream: Σ angle², count
  for (const PoseMessage& m : receiver.messages()) {
    const auto i = static_cast<std::size_t>(std::lround(m.sample_time * optical.rate_hz));
    if (i >= tracker.truth.size() || m.sample_time < 3.0) continue;  // after the estimates settled
    const double a = so3::rotation_angle(m.orientation, tracker.truth[i]);
    squared[m.stream].first += a * a;
    ++squared[m.stream].second;
  }
  const auto rms_deg = [&](std::uint32_t id) {
    const auto& [sum, count] = squared[id];
    return count ? std::sqrt(sum / static_cast<double>(count)) * 180.0 / M_PI : 1e9;
  };
  const double with_imu = rms_deg(1), alone = rms_deg(3);
  std::printf("optical 120 Hz, 1 deg jitter: faired with the IMU %.3f deg, alone %.3f deg; offset %.2f ms, matched %llu, unmatched %llu\n",
              with_imu, alone, 1e3 * paired.engine.gyro.time_offset_s,
              static_cast<unsigned long long>(paired.gyro_pairing->matched),
              static_cast<unsigned long long>(paired.gyro_pairing->unmatched));
  EXPECT_LT(with_imu, 0.5 * alone) << "with the IMU " << with_imu << "°, alone " << alone << "°";

  const std::vector<std::string> lines = counter_lines(stats, {}, 1.0);
  EXPECT_NE(lines[0].find("gyro-aided from 'imu' (matched "), std::string::npos) << lines[0];
  EXPECT_NE(status_line(stats, {}, 1.0).find(" gyro from imu unmatched "), std::string::npos) << status_line(stats, {}, 1.0);
}

// Each stream has its own engine role (docs/operations.md, "Threads and memory"): while one
// stream's driver thread is held up in its pass (here 600 ms in the fairing of one sample, as a
// thread the machine stops for a while), the other stream's driver goes on fairing and publishing
// its own samples. With one role for all streams the second stream's samples waited in its ring
// for the holder.
TEST(Pipeline, AStreamHeldUpInItsPassDoesNotHoldUpTheOthers) {
  UdpCollector receiver;
  std::string text = "[daemon]\nsession_id = " + std::to_string(kSession) + "\nfair_on = \"driver\"\n";
  for (int id = 1; id <= 2; ++id)
    text += "[[stream]]\nid = " + std::to_string(id) + "\nname = \"s" + std::to_string(id) + "\"\nring_capacity = 4096\n" +
            "[stream.driver]\ntype = \"replay\"\npath = \"" + kDemoCsv.string() + "\"\n[stream.engine]\nwindow = 16\nlag = 0\n";
  text += "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(receiver.port()) + "\"]\n";
  std::atomic<int> seen{0};
  std::atomic<bool> held{false}, released{false};
  PipelineHooks hooks;
  hooks.before_engine_sample = [&](std::uint32_t stream_id) {
    if (stream_id != 1 || seen.fetch_add(1) != 100) return;
    held.store(true);
    std::this_thread::sleep_for(600ms);
    released.store(true);
  };
  Pipeline pipeline(parse_config(text, "/virtual/held-up.toml"), kSession, {}, false, hooks);
  pipeline.start();
  ASSERT_TRUE(wait_until([&] { return held.load(); }, 10s)) << "stream 1 never reached its 100th sample";
  std::this_thread::sleep_for(100ms);
  const std::vector<StreamStats> before = pipeline.stats();
  std::this_thread::sleep_for(300ms);
  const std::vector<StreamStats> after = pipeline.stats();
  const bool still_held = !released.load();
  pipeline.stop();
  ASSERT_TRUE(still_held) << "the machine was too slow to look within the 600 ms";
  EXPECT_EQ(after[0].published, before[0].published) << "stream 1 is held up";
  // 0.3 s of a 286 Hz replay: 86 poses; at least half of them, whatever the machine's load.
  EXPECT_GE(after[1].published - before[1].published, 43u) << "stream 2 waited for stream 1";
}

// The hand-over options ([daemon] fair_on, publish_on, spin_us, wake, cpu_affinity; [[stream]] busy_poll;
// [[output]] sendmmsg; docs/config.md): whichever is chosen, three replayed streams to an output
// with two destinations are published exactly once each, in order per stream, every counter adds
// up, and every stage of the latency histograms saw every sample (the hand-off only when a
// publisher thread takes the poses over).
struct HandOverOptions {
  const char* name;
  const char* daemon_keys;
  const char* stream_keys;
  const char* output_keys;
  bool engine_publishes;
};

class PipelineHandOver : public ::testing::TestWithParam<HandOverOptions> {};

TEST_P(PipelineHandOver, EveryPoseIsPublishedOnceInOrderAndEveryStageCounted) {
  const HandOverOptions& o = GetParam();
  UdpCollector first, second;
  std::string text = "[daemon]\nsession_id = " + std::to_string(kSession) + "\n" + o.daemon_keys;
  for (int id = 1; id <= 3; ++id)
    text += "[[stream]]\nid = " + std::to_string(id) + "\nname = \"s" + std::to_string(id) + "\"\nring_capacity = 4096\n" +
            o.stream_keys + "[stream.driver]\ntype = \"replay\"\npath = \"" + kDemoCsv.string() +
            "\"\ntiming = \"fast\"\n[stream.engine]\nwindow = 16\nlag = 0\n";
  text += "[[output]]\ndestinations = [\"127.0.0.1:" + std::to_string(first.port()) + "\", \"127.0.0.1:" +
          std::to_string(second.port()) + "\"]\n" + o.output_keys;
  const DaemonConfig config = parse_config(text, "/virtual/hand-over.toml");
  std::vector<StreamStats> stats;
  StageLatencySnapshot stages;
  {
    Pipeline pipeline(config, kSession, {}, false, {});
    EXPECT_TRUE(pipeline.start().empty());
    EXPECT_TRUE(wait_until([&] { return pipeline.sources_ended(); }, 30s)) << "the replays did not end";
    pipeline.stop();
    stats = pipeline.stats();
    stages = pipeline.stage_latency();
  }
  ASSERT_EQ(stats.size(), 3u);
  for (const StreamStats& s : stats) {
    SCOPED_TRACE(s.name);
    EXPECT_EQ(s.received, kDemoSamples);
    EXPECT_EQ(s.ring_dropped + s.publish_dropped + s.rejected + s.out_of_order, 0u);
    EXPECT_EQ(s.emitted, kDemoSamples);
    EXPECT_EQ(s.published, kDemoSamples);
    EXPECT_EQ(s.send_failures, 0u);
    EXPECT_EQ(s.latency.count, s.published);
  }
  const std::uint64_t all = 3 * kDemoSamples;
  EXPECT_EQ(stages.ring_wait.count, all);
  EXPECT_EQ(stages.engine.count, all);  // lag 0: every sample emits its pose
  EXPECT_EQ(stages.encode.count, all);
  EXPECT_EQ(stages.send.count, all);
  EXPECT_EQ(stages.hand_off.count, o.engine_publishes ? 0u : all);

  const std::vector<double> times = demo_times();
  for (UdpCollector* receiver : {&first, &second}) {
    receiver->drain(100ms);  // the pipeline has stopped: what is in flight is in the socket buffer
    const std::vector<PoseMessage> got = receiver->messages();
    EXPECT_EQ(got.size(), all);
    std::map<std::uint32_t, std::uint64_t> next;  // per stream: the sequence number due
    for (const PoseMessage& m : got) {
      std::uint64_t& due = next[m.stream];
      ASSERT_EQ(m.sequence, due) << "stream " << m.stream << ": a pose missing, repeated or out of order";
      ASSERT_LT(m.sequence, times.size());
      ASSERT_EQ(m.sample_time, times[m.sequence]);
      ++due;
    }
    EXPECT_EQ(next, (std::map<std::uint32_t, std::uint64_t>{{1, kDemoSamples}, {2, kDemoSamples}, {3, kDemoSamples}}));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Options, PipelineHandOver,
    ::testing::Values(HandOverOptions{"EnginePublishes", "publish_on = \"engine\"\n", "", "", true},
                      HandOverOptions{"PublisherThread", "publish_on = \"publisher\"\n", "", "", false},
                      HandOverOptions{"EngineSpins", "publish_on = \"engine\"\nspin_us = 200\n", "", "", true},
                      HandOverOptions{"PublisherSpinsWakingPerSample",
                                      "publish_on = \"publisher\"\nspin_us = 200\nwake = \"per-sample\"\n", "", "", false},
                      HandOverOptions{"BusyPoll", "publish_on = \"engine\"\n", "busy_poll = true\n", "", true},
                      HandOverOptions{"PinnedToCpu0", "publish_on = \"publisher\"\ncpu_affinity = [0]\n", "", "", false},
                      HandOverOptions{"SendtoEachDestination", "publish_on = \"engine\"\n", "", "sendmmsg = false\n", true},
                      HandOverOptions{"DriversFairAndPublish", "fair_on = \"driver\"\npublish_on = \"engine\"\n", "", "", true},
                      HandOverOptions{"DriversFairForAPublisherThread", "fair_on = \"driver\"\npublish_on = \"publisher\"\n",
                                      "", "", false},
                      HandOverOptions{"DriversFairWhileTheEngineBusyPolls", "fair_on = \"driver\"\n", "busy_poll = true\n", "",
                                      true}),
    [](const ::testing::TestParamInfo<HandOverOptions>& i) { return std::string(i.param.name); });

}  // namespace
}  // namespace posefair::daemon
