#pragma once
// The replay driver: plays a recording back as if its devices were live. The source is a
// sample log (sample_log.hpp, with its rotated parts) or a pose file (TUM, CSV, BVH through
// read_pose_file). Every sample goes out through SampleSink::push with receive_time set to
// CLOCK_MONOTONIC at delivery, exactly as a device driver does; see docs/recording.md.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <stop_token>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/formats/pose_file.hpp"
#include "posefair/formats/sample_log.hpp"

namespace posefair::drivers {

enum class ReplayTiming {
  Original,          // each sample at its recorded offset from the first, divided by `speed`
  AsFastAsPossible,  // no waiting at all
};

// Which recorded time spaces the deliveries under ReplayTiming::Original.
enum class ReplaySchedule {
  Time,         // Sample::time (the engine's time)
  ReceiveTime,  // Sample::receive_time: reproduces the arrival pattern of a live recording
                // (bursts, jitter); falls back to Time when the source has none (pose files)
};

struct ReplayOptions {
  ReplayTiming timing = ReplayTiming::Original;
  double speed = 1.0;  // Original only: 2.0 plays twice as fast. Finite and > 0.
  ReplaySchedule schedule = ReplaySchedule::Time;
  // Play the recording again and again. Round k's times (and device times) are shifted by
  // k · P, P = span of the recorded times + their mean spacing (1 s for a single sample), so
  // they keep increasing; sequence numbers continue (each stream's are shifted by k · (its
  // highest - lowest + 1)).
  bool loop = false;
  std::uint64_t max_rounds = 0;  // with loop: stop after this many rounds; 0 = until stopped
  // Pose files: the stream id every sample gets (sequence numbers are 0, 1, ... in file order).
  std::uint32_t stream_id = 0;
  formats::ReadOptions pose;  // pose files: format (else by extension), BVH joint, CSV options
  // Sample logs: also play "<base>.1.pflog", "<base>.2.pflog" ... after the file given.
  bool follow_rotation = true;
};

// A replay plays a sample log (formats::is_sample_log_file: named *.pflog, or starting with the
// log's magic) as such, anything else as a pose file.

class ReplayDriver final : public Driver {
 public:
  // Loads the whole source now. A file named *.pflog or starting with the sample log magic
  // (whatever its name) is read as a sample log, anything else as a pose file. Throws SampleLogError or
  // PoseFileError for unreadable sources, std::invalid_argument for bad options. Damage after
  // a log's header does not throw: the intact part is played and warnings() says what was
  // left out.
  explicit ReplayDriver(const std::filesystem::path& source, ReplayOptions options = {});
  // Plays samples given in memory, in this order (stream ids, sequence numbers and times as given).
  ReplayDriver(std::vector<Sample> samples, ReplayOptions options = {}, std::string name = "replay");

  std::string_view name() const override { return name_; }

  // Plays the recording (once, max_rounds times or until stopped, per the options) into
  // `sink`. Returns at the end, or within a few milliseconds of a stop request, including
  // during a long wait for the next sample. Each run() starts again from the beginning, its
  // timing relative to its own start. One run() at a time.
  void run(std::stop_token stop, SampleSink& sink) override;

  // Counters, readable from any thread while run() goes on.
  std::uint64_t delivered() const { return delivered_.load(std::memory_order_relaxed); }  // push() true
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }      // push() false
  std::uint64_t rounds_completed() const { return rounds_.load(std::memory_order_relaxed); }

  // The recording as loaded (one round, before any re-basing).
  const std::vector<Sample>& samples() const { return samples_; }
  // The log's stream table; for a pose file one stream (stream_id, the file's stem, "replay of <path>").
  const std::vector<formats::StreamInfo>& streams() const { return streams_; }
  // What was accepted while loading: log damage (the problem messages), pose file quirks.
  const std::vector<std::string>& warnings() const { return warnings_; }
  const ReplayOptions& options() const { return options_; }

 private:
  void prepare();

  ReplayOptions options_;
  std::string name_;
  std::vector<Sample> samples_;
  std::vector<formats::StreamInfo> streams_;
  std::vector<std::string> warnings_;
  std::vector<double> due_;                 // seconds after the first sample, at speed 1
  std::vector<std::uint64_t> sequence_step_;  // per sample: its stream's sequence shift per round
  double time_period_ = 1.0;                // loop: shift of the times per round
  double schedule_period_ = 1.0;            // loop: shift of the schedule per round
  std::atomic<std::uint64_t> delivered_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> rounds_{0};
};

}  // namespace posefair::drivers
