#include "posefair/drivers/synthetic_driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "posefair/core/synthetic_motion.hpp"

namespace posefair::drivers {
namespace {

constexpr double kMaxBlockSeconds = 10.0;

}  // namespace

SyntheticDriver::SyntheticDriver(const SyntheticOptions& o) {
  if (!std::isfinite(o.rate_hz) || o.rate_hz <= 0.0) throw std::invalid_argument("synthetic driver: rate_hz must be finite and > 0");
  if (!std::isfinite(o.duration) || o.duration < 0.0) throw std::invalid_argument("synthetic driver: duration must be finite and >= 0");
  if (!std::isfinite(o.rotation_noise) || o.rotation_noise < 0.0)
    throw std::invalid_argument("synthetic driver: rotation_noise must be finite and >= 0");
  if (!(o.phase >= 0.0 && o.phase < 1.0)) throw std::invalid_argument("synthetic driver: phase must be in [0, 1)");
  start_delay_ = o.as_fast_as_possible ? 0.0 : o.phase / o.rate_hz;

  // A finite duration is split into equal blocks of at most 10 s, so the rounds end on it.
  const double rounds = o.duration > 0.0 ? std::ceil(o.duration / kMaxBlockSeconds) : 0.0;
  const double block_seconds = o.duration > 0.0 ? o.duration / rounds : kMaxBlockSeconds;
  SyntheticMotionSpec spec;
  spec.samples = static_cast<std::size_t>(std::max(1.0, std::round(block_seconds * o.rate_hz)));
  spec.sample_rate_hz = o.rate_hz;
  spec.cycles = 0.2 * block_seconds;  // about one slow swing every 5 s
  spec.rotation_noise = o.rotation_noise;
  spec.with_position = o.with_position;
  spec.cube_size = 1.0;         // metres
  spec.position_noise = 0.001;  // 1 mm
  spec.seed = o.seed;
  const SyntheticMotion motion = make_synthetic_motion(spec);

  std::vector<Sample> samples(spec.samples);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    Sample& s = samples[i];
    s.stream_id = o.stream_id;
    s.sequence = i;
    s.time = motion.noisy.time[i];
    s.orientation = motion.noisy.orientation[i];
    if (o.with_position) {
      s.position = motion.noisy.position[i];
      s.flags |= kHasPosition;
    }
  }
  ReplayOptions ro;
  ro.timing = o.as_fast_as_possible ? ReplayTiming::AsFastAsPossible : ReplayTiming::Original;
  ro.loop = true;
  ro.max_rounds = static_cast<std::uint64_t>(rounds);
  ro.stream_id = o.stream_id;
  char name[96];
  std::snprintf(name, sizeof name, "synthetic:%gHz", o.rate_hz);
  name_ = name;
  replay_ = std::make_unique<ReplayDriver>(std::move(samples), ro, name_);
}

void SyntheticDriver::run(std::stop_token stop, SampleSink& sink) {
  if (start_delay_ > 0.0) {
    std::mutex mutex;
    std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop
    std::unique_lock lock(mutex);
    wake.wait_for(lock, stop, std::chrono::duration<double>(start_delay_), [] { return false; });
    if (stop.stop_requested()) return;
  }
  replay_->run(stop, sink);
}

}  // namespace posefair::drivers
