// The replay driver: a recording through SampleSink::push, timed or as fast as possible,
// looped, stopped, with a sink that drops.
#include <gtest/gtest.h>
#include <time.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <stop_token>
#include <thread>
#include <vector>

#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/replay_driver.hpp"
#include "posefair/formats/sample_log.hpp"
#include "../formats/sample_log_test_support.hpp"

namespace posefair::drivers {
namespace {

namespace fs = std::filesystem;
using formats::testing::bit_identical;
using formats::testing::make_samples;
using formats::testing::ScratchDir;

double monotonic_now() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Keeps everything it is given; optionally refuses some; optionally stops the run.
class CollectingSink : public SampleSink {
 public:
  CollectingSink() { samples.reserve(10000); }
  bool push(const Sample& s) override {
    const std::size_t n = offered.fetch_add(1) + 1;
    if (stop_after != 0 && n >= stop_after) stopper->request_stop();
    if (refuse_every != 0 && n % refuse_every == 0) return false;
    samples.push_back(s);
    {
      std::lock_guard lock(mutex);
      first_arrived = true;
    }
    arrived.notify_all();
    return true;
  }
  std::vector<Sample> samples;
  std::atomic<std::size_t> offered{0};
  std::size_t refuse_every = 0;
  std::size_t stop_after = 0;
  std::stop_source* stopper = nullptr;
  std::mutex mutex;
  std::condition_variable arrived;
  bool first_arrived = false;
};

ReplayOptions fast() {
  ReplayOptions o;
  o.timing = ReplayTiming::AsFastAsPossible;
  return o;
}

// `n` samples of one stream, `dt` apart.
std::vector<Sample> evenly(std::size_t n, double dt, std::uint32_t stream = 1, std::uint64_t first_sequence = 0) {
  std::vector<Sample> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i].stream_id = stream;
    out[i].sequence = first_sequence + i;
    out[i].time = 20.0 + dt * static_cast<double>(i);
  }
  return out;
}

void write_log(const fs::path& path, const std::vector<Sample>& samples, formats::SampleLogWriterOptions o = {}) {
  formats::SampleLogHeader h;
  h.streams = {{10, "a", "test"}, {11, "b", "test"}, {12, "c", "test"}};
  o.sync = false;
  formats::SampleLogWriter w(path, h, o);
  for (const Sample& s : samples) w.append(s);
}

TEST(ReplayDriver, AsFastAsPossibleDeliversEverySampleInOrderLikeADevice) {
  ScratchDir dir;
  const std::vector<Sample> recorded = make_samples(600);
  write_log(dir / "run.pflog", recorded);
  ReplayDriver driver(dir / "run.pflog", fast());
  EXPECT_EQ(driver.name(), "replay:run.pflog");
  ASSERT_EQ(driver.streams().size(), 3u);
  EXPECT_EQ(driver.streams()[1].name, "b");
  EXPECT_TRUE(driver.warnings().empty());

  CollectingSink sink;
  const double before = monotonic_now();
  driver.run(std::stop_token{}, sink);
  const double after = monotonic_now();
  ASSERT_EQ(sink.samples.size(), recorded.size());
  double previous = before;
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    Sample expected = recorded[i];
    const Sample& got = sink.samples[i];
    EXPECT_GE(got.receive_time, previous);  // CLOCK_MONOTONIC at delivery
    EXPECT_LE(got.receive_time, after);
    previous = got.receive_time;
    expected.receive_time = got.receive_time;
    ASSERT_TRUE(bit_identical(got, expected)) << i;  // all else as recorded
  }
  EXPECT_EQ(driver.delivered(), recorded.size());
  EXPECT_EQ(driver.dropped(), 0u);
  EXPECT_EQ(driver.rounds_completed(), 1u);
}

// The golden WitMotion log (tests/replay/witmotion-wt901.log: time, acceleration and quaternion
// packets, some quaternions damaged) decoded, recorded and replayed: every sample comes back
// with its raw readings, the raw-only ones (a lost quaternion's acceleration) included.
TEST(ReplayDriver, RawReadingsOfARecordedDeviceReplayIntact) {
  std::ifstream in(std::string(POSEFAIR_SOURCE_DIR) + "/tests/replay/witmotion-wt901.log", std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t data = all.find("# data:\n");
  ASSERT_NE(data, std::string::npos);
  struct Recorder final : DecodedSink {
    std::vector<Sample> samples;
    void on_sample(const DecodedSample& d) override {
      Sample s;
      s.stream_id = 10;
      s.sequence = samples.size();
      s.time = 0.01 * static_cast<double>(samples.size());
      fill_sample(d, s);
      samples.push_back(s);
    }
  } recorder;
  const std::string bytes = all.substr(data + 8);
  make_decoder("witmotion")->feed({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, recorder);
  const std::vector<Sample>& recorded = recorder.samples;
  std::size_t with_accel = 0, raw_only = 0;
  for (const Sample& s : recorded) {
    with_accel += s.has_accel() && s.has_orientation();
    raw_only += !s.has_orientation();
  }
  EXPECT_EQ(with_accel, 293u);  // as its .chk: 297 orientations, 4 of them lost their acceleration packet,
  EXPECT_EQ(raw_only, 4u);      // and 4 accelerations lost their quaternion

  ScratchDir dir;
  write_log(dir / "wit.pflog", recorded);
  ReplayDriver driver(dir / "wit.pflog", fast());
  CollectingSink sink;
  driver.run(std::stop_token{}, sink);
  ASSERT_EQ(sink.samples.size(), recorded.size());
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    Sample expected = recorded[i];
    expected.receive_time = sink.samples[i].receive_time;
    ASSERT_TRUE(bit_identical(sink.samples[i], expected)) << i;
  }
}

TEST(ReplayDriver, OriginalTimingFollowsTheRecordingAtTheGivenSpeed) {
  const std::vector<Sample> recorded = evenly(51, 0.01);  // 0.5 s
  ReplayOptions o;
  o.timing = ReplayTiming::Original;
  o.speed = 10.0;
  ReplayDriver driver(recorded, o);
  CollectingSink sink;
  const auto t0 = std::chrono::steady_clock::now();
  const double start = monotonic_now();
  driver.run(std::stop_token{}, sink);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GT(ms, 30.0);
  EXPECT_LT(ms, 400.0);
  ASSERT_EQ(sink.samples.size(), 51u);
  for (std::size_t i = 0; i < 51; ++i) {
    const double due = 0.001 * static_cast<double>(i);  // 10 ms apart at speed 10
    EXPECT_GE(sink.samples[i].receive_time - start, due - 1e-4) << i << ": delivered before it was due";
    EXPECT_EQ(sink.samples[i].time, recorded[i].time);
  }
}

TEST(ReplayDriver, ReceiveTimeScheduleReplaysTheArrivalPattern) {
  std::vector<Sample> recorded = evenly(4, 0.0);  // no spacing in `time` at all
  for (std::size_t i = 0; i < 4; ++i) recorded[i].receive_time = 300.0 + 0.1 * static_cast<double>(i);
  ReplayOptions o;
  o.speed = 10.0;
  o.schedule = ReplaySchedule::ReceiveTime;
  ReplayDriver driver(recorded, o);
  CollectingSink sink;
  const double start = monotonic_now();
  driver.run(std::stop_token{}, sink);
  ASSERT_EQ(sink.samples.size(), 4u);
  EXPECT_GE(sink.samples[3].receive_time - start, 0.03 - 1e-4);
  EXPECT_LT(sink.samples[3].receive_time - start, 0.4);
}

TEST(ReplayDriver, LoopContinuesTimesAndSequenceNumbers) {
  std::vector<Sample> recorded = evenly(20, 0.01, 1, 100);     // sequences 100..119
  const std::vector<Sample> other = evenly(10, 0.02, 2, 7);    // sequences 7..16
  recorded.insert(recorded.end(), other.begin(), other.end());  // two streams, not interleaved
  ReplayOptions o = fast();
  o.loop = true;
  o.max_rounds = 3;
  ReplayDriver driver(recorded, o);
  CollectingSink sink;
  driver.run(std::stop_token{}, sink);
  ASSERT_EQ(sink.samples.size(), 90u);
  EXPECT_EQ(driver.rounds_completed(), 3u);
  EXPECT_EQ(driver.delivered(), 90u);
  for (std::uint32_t stream : {1u, 2u}) {
    std::vector<Sample> mine;
    for (const Sample& s : sink.samples) {
      if (s.stream_id == stream) mine.push_back(s);
    }
    ASSERT_EQ(mine.size(), stream == 1 ? 60u : 30u);
    for (std::size_t i = 1; i < mine.size(); ++i) {
      EXPECT_GT(mine[i].time, mine[i - 1].time) << stream << " " << i;
      EXPECT_EQ(mine[i].sequence, mine[i - 1].sequence + 1) << stream << " " << i;
    }
    EXPECT_EQ(mine.front().sequence, stream == 1 ? 100u : 7u);
  }
  // Round k is shifted by k · (span 0.19 s + mean spacing 0.19/29 s).
  const double period = 0.19 + 0.19 / 29.0;
  EXPECT_NEAR(sink.samples[30].time - sink.samples[0].time, period, 1e-12);
  EXPECT_NEAR(sink.samples[60].time - sink.samples[0].time, 2 * period, 1e-12);
}

TEST(ReplayDriver, LoopWithoutALimitRunsUntilStopped) {
  ReplayOptions o = fast();
  o.loop = true;
  ReplayDriver driver(evenly(7, 0.01), o);
  std::stop_source stop;
  CollectingSink sink;
  sink.stop_after = 1000;
  sink.stopper = &stop;
  driver.run(stop.get_token(), sink);
  EXPECT_EQ(sink.samples.size(), 1000u);
  EXPECT_EQ(sink.samples.back().sequence, 999u);
  EXPECT_EQ(driver.rounds_completed(), 142u);  // 1000 = 142 · 7 + 6
}

TEST(ReplayDriver, AStopDuringALongWaitReturnsQuickly) {
  std::vector<Sample> recorded = evenly(2, 60.0);  // the second sample is a minute away
  ReplayDriver driver(recorded, {});
  CollectingSink sink;
  std::jthread thread([&](std::stop_token stop) { driver.run(stop, sink); });
  {
    std::unique_lock lock(sink.mutex);
    ASSERT_TRUE(sink.arrived.wait_for(lock, std::chrono::seconds(10), [&] { return sink.first_arrived; }));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // well into the wait
  const auto t0 = std::chrono::steady_clock::now();
  thread.request_stop();
  thread.join();
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(ms, 200.0);
  EXPECT_EQ(driver.delivered(), 1u);
  EXPECT_EQ(sink.samples.size(), 1u);
}

TEST(ReplayDriver, ARequestedStopBeforeTheStartDeliversNothing) {
  std::stop_source stop;
  stop.request_stop();
  ReplayDriver driver(evenly(5, 0.01), fast());
  CollectingSink sink;
  driver.run(stop.get_token(), sink);
  EXPECT_EQ(driver.delivered(), 0u);
}

TEST(ReplayDriver, SamplesTheSinkRefusesAreCountedAsDropped) {
  ReplayDriver driver(evenly(100, 0.01), fast());
  CollectingSink sink;
  sink.refuse_every = 4;
  driver.run(std::stop_token{}, sink);
  EXPECT_EQ(driver.delivered(), 75u);
  EXPECT_EQ(driver.dropped(), 25u);
  EXPECT_EQ(sink.samples.size(), 75u);
  EXPECT_EQ(sink.samples[3].sequence, 4u);  // sequence 3 was the one dropped: a gap, as from a device
}

TEST(ReplayDriver, TumFileAsFastAsPossible) {
  ReplayOptions o = fast();
  o.stream_id = 5;
  const fs::path tum = fs::path(POSEFAIR_SOURCE_DIR) / "tests/data/tum/fr2_desk_ORB.txt";  // an excerpt: 50 poses
  ReplayDriver driver(tum, o);
  EXPECT_EQ(driver.name(), "replay:fr2_desk_ORB.txt");
  ASSERT_EQ(driver.streams().size(), 1u);
  EXPECT_EQ(driver.streams()[0].id, 5u);
  CollectingSink sink;
  driver.run(std::stop_token{}, sink);
  ASSERT_EQ(sink.samples.size(), 50u);
  EXPECT_EQ(driver.delivered(), 50u);
  const formats::PoseFile file = formats::read_pose_file(tum, {});
  for (std::size_t i = 0; i < sink.samples.size(); ++i) {
    const Sample& s = sink.samples[i];
    ASSERT_EQ(s.stream_id, 5u);
    ASSERT_EQ(s.sequence, i);
    ASSERT_EQ(s.time, file.poses().time[i]);
    ASSERT_EQ(s.flags, static_cast<std::uint32_t>(kHasPosition));
    ASSERT_EQ(s.orientation.coeffs(), file.poses().orientation[i].coeffs());
    ASSERT_EQ(s.position, file.poses().position[i]);
  }
  EXPECT_DOUBLE_EQ(sink.samples.front().time, 1311868164.363181);
}

TEST(ReplayDriver, CsvFileGetsTheStreamIdAndNoPositionsWhenItHasNone) {
  ScratchDir dir;
  const fs::path csv = dir / "imu.csv";
  {
    std::ofstream out(csv);
    out << "t,qw,qx,qy,qz\n0.0,1,0,0,0\n0.01,0.9998,0.02,0,0\n0.02,0.9992,0.04,0,0\n";
  }
  ReplayOptions o = fast();
  o.stream_id = 3;
  ReplayDriver driver(csv, o);
  CollectingSink sink;
  driver.run(std::stop_token{}, sink);
  ASSERT_EQ(sink.samples.size(), 3u);
  for (const Sample& s : sink.samples) {
    EXPECT_EQ(s.stream_id, 3u);
    EXPECT_EQ(s.flags, 0u);
    EXPECT_EQ(s.position, Vec3::Zero());
  }
  EXPECT_EQ(sink.samples[2].time, 0.02);
}

TEST(ReplayDriver, ARotatedLogPlaysAllItsParts) {
  ScratchDir dir;
  const std::vector<Sample> recorded = make_samples(95);
  formats::SampleLogWriterOptions o;
  o.max_file_bytes = 2000;
  write_log(dir / "run.pflog", recorded, o);
  ASSERT_GT(formats::sample_log_files(dir / "run.pflog").size(), 3u);
  ReplayDriver all(dir / "run.pflog", fast());
  EXPECT_EQ(all.samples().size(), 95u);
  ReplayOptions first_only = fast();
  first_only.follow_rotation = false;
  ReplayDriver one(dir / "run.pflog", first_only);
  EXPECT_LT(one.samples().size(), 95u);
}

TEST(ReplayDriver, ADamagedLogPlaysItsIntactPartAndSaysSo) {
  ScratchDir dir;
  const std::vector<Sample> recorded = make_samples(10);
  write_log(dir / "run.pflog", recorded);
  fs::resize_file(dir / "run.pflog", fs::file_size(dir / "run.pflog") - 30);  // a crash mid-record
  ReplayDriver driver(dir / "run.pflog", fast());
  EXPECT_EQ(driver.samples().size(), 9u);
  ASSERT_EQ(driver.warnings().size(), 1u);
  EXPECT_NE(driver.warnings()[0].find("truncated record (expected 105 bytes, 75 present) (75 bytes not read)"),
            std::string::npos)
      << driver.warnings()[0];
}

TEST(ReplayDriver, BadOptionsAndSourcesThrow) {
  ReplayOptions o;
  o.speed = 0.0;
  EXPECT_THROW(ReplayDriver(evenly(3, 0.01), o), std::invalid_argument);
  o.speed = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ReplayDriver(evenly(3, 0.01), o), std::invalid_argument);
  EXPECT_THROW(ReplayDriver(fs::path("/nonexistent/run.pflog")), formats::SampleLogError);
  EXPECT_THROW(ReplayDriver(fs::path("/nonexistent/run.txt")), formats::PoseFileError);
  ReplayDriver empty(std::vector<Sample>{}, {});
  CollectingSink sink;
  empty.run(std::stop_token{}, sink);
  EXPECT_EQ(empty.delivered(), 0u);
}

}  // namespace
}  // namespace posefair::drivers
