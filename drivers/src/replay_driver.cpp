// The replay driver: a recording played back through SampleSink::push like a live device.
#include "posefair/drivers/replay_driver.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "monotonic_clock.hpp"

namespace posefair::drivers {

namespace {

// Span + mean spacing of a set of values (the shift per loop round); 1 s when they do not span.
double loop_period(double lo, double hi, std::size_t n) {
  if (!(hi > lo) || n < 2) return 1.0;
  const double span = hi - lo;
  return span + span / static_cast<double>(n - 1);
}

}  // namespace

ReplayDriver::ReplayDriver(const std::filesystem::path& source, ReplayOptions options)
    : options_(std::move(options)), name_("replay:" + source.filename().string()) {
  if (formats::is_sample_log_file(source)) {
    formats::SampleLogContents log = options_.follow_rotation ? formats::read_sample_log_set(source) : formats::read_sample_log(source);
    samples_ = std::move(log.samples);
    streams_ = std::move(log.header.streams);
    for (const formats::SampleLogProblem& p : log.stats.problems) {
      warnings_.push_back(p.message + " (" + std::to_string(p.unread_bytes) + " bytes not read)");
    }
    if (log.stats.unknown_records > 0) {
      warnings_.push_back(source.string() + ": " + std::to_string(log.stats.unknown_records) +
                          " records of kinds this version does not know were skipped");
    }
  } else {
    const formats::PoseFile file = formats::read_pose_file(source, options_.pose);
    const PoseSequence& poses = file.poses();
    samples_.resize(poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      Sample& s = samples_[i];
      s.stream_id = options_.stream_id;
      s.sequence = i;
      s.time = poses.time[i];
      s.orientation = poses.orientation[i];
      if (poses.has_position()) {
        s.position = poses.position[i];
        s.flags |= kHasPosition;
      }
    }
    streams_.push_back(formats::StreamInfo{options_.stream_id, source.stem().string(),
                                  "replay of " + source.string() + " (" + std::string(to_string(file.format())) + ")"});
    warnings_ = file.warnings();
    if (file.skipped_rows() > 0) {
      warnings_.push_back(source.string() + ": " + std::to_string(file.skipped_rows()) +
                          " rows without a quaternion skipped");
    }
  }
  prepare();
}

ReplayDriver::ReplayDriver(std::vector<Sample> samples, ReplayOptions options, std::string name)
    : options_(std::move(options)), name_(std::move(name)), samples_(std::move(samples)) {
  std::map<std::uint32_t, bool> seen;
  for (const Sample& s : samples_) {
    if (!seen[s.stream_id]) {
      seen[s.stream_id] = true;
      streams_.push_back(formats::StreamInfo{s.stream_id, "stream " + std::to_string(s.stream_id), name_});
    }
  }
  prepare();
}

void ReplayDriver::prepare() {
  if (!(options_.speed > 0.0) || !std::isfinite(options_.speed)) {
    throw std::invalid_argument("replay: speed must be finite and > 0");
  }
  const std::size_t n = samples_.size();

  // The schedule: seconds after the first sample (at speed 1), never going backwards (samples
  // of several streams may interleave slightly out of order; a late one goes out at once).
  bool use_receive = options_.schedule == ReplaySchedule::ReceiveTime &&
                     std::any_of(samples_.begin(), samples_.end(), [](const Sample& s) { return s.receive_time != 0.0; });
  due_.assign(n, 0.0);
  double key0 = std::numeric_limits<double>::quiet_NaN();
  double previous = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double key = use_receive ? samples_[i].receive_time : samples_[i].time;
    if (std::isfinite(key)) {
      if (std::isnan(key0)) key0 = key;
      previous = std::max(previous, std::min(key - key0, 1e9));  // ~30 years: keeps the clock sane
    }
    due_[i] = previous;
  }
  schedule_period_ = loop_period(0.0, n > 0 ? due_.back() : 0.0, n);

  // Loop re-basing of the recorded times.
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  std::size_t finite = 0;
  for (const Sample& s : samples_) {
    if (!std::isfinite(s.time)) continue;
    lo = std::min(lo, s.time);
    hi = std::max(hi, s.time);
    ++finite;
  }
  time_period_ = loop_period(lo, hi, finite);

  // Per stream: how far its sequence numbers move per round.
  std::map<std::uint32_t, std::pair<std::uint64_t, std::uint64_t>> range;
  for (const Sample& s : samples_) {
    auto [it, inserted] = range.try_emplace(s.stream_id, s.sequence, s.sequence);
    if (!inserted) {
      it->second.first = std::min(it->second.first, s.sequence);
      it->second.second = std::max(it->second.second, s.sequence);
    }
  }
  sequence_step_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& [low, high] = range[samples_[i].stream_id];
    sequence_step_[i] = high - low + 1;
  }
}

void ReplayDriver::run(std::stop_token stop, SampleSink& sink) {
  using Clock = std::chrono::steady_clock;
  if (samples_.empty()) return;
  const bool timed = options_.timing == ReplayTiming::Original;
  const Clock::time_point start = Clock::now();
  std::mutex mutex;
  std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop

  for (std::uint64_t round = 0;; ++round) {
    if (round > 0 && !options_.loop) return;
    if (options_.loop && options_.max_rounds != 0 && round >= options_.max_rounds) return;
    const double round_d = static_cast<double>(round);
    for (std::size_t i = 0; i < samples_.size(); ++i) {
      if (stop.stop_requested()) return;
      if (timed) {
        const double due = (round_d * schedule_period_ + due_[i]) / options_.speed;
        const Clock::time_point deadline =
            start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(std::min(due, 1e9)));
        if (Clock::now() < deadline) {
          std::unique_lock lock(mutex);
          wake.wait_until(lock, stop, deadline, [] { return false; });
        }
        if (stop.stop_requested()) return;
      }
      Sample s = samples_[i];
      if (round > 0) {
        s.time += round_d * time_period_;
        if ((s.flags & kHasDeviceTime) != 0) s.device_time += round_d * time_period_;
        s.sequence += round * sequence_step_[i];
      }
      s.receive_time = monotonic_seconds();
      if (sink.push(s)) {
        delivered_.fetch_add(1, std::memory_order_relaxed);
      } else {
        dropped_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    rounds_.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace posefair::drivers
