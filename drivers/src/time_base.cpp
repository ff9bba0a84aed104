// The engine's time for live devices: receive time, or the device clock once trusted. The rule
// is stated in time_base.hpp.
#include "posefair/drivers/time_base.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace posefair::drivers {

std::optional<TimeSource> parse_time_source(std::string_view text) {
  if (text == "auto") return TimeSource::Auto;
  if (text == "receive") return TimeSource::Receive;
  if (text == "device") return TimeSource::Device;
  return std::nullopt;
}

std::string_view to_string(TimeSource source) {
  switch (source) {
    case TimeSource::Auto: return "auto";
    case TimeSource::Receive: return "receive";
    case TimeSource::Device: return "device";
  }
  return "auto";
}

TimeBase::TimeBase(TimeSource source, const TimeBaseOptions& options)
    : source_(source), options_(options), block_length_(options.window / kBlocksPerWindow) {
  if (!(options_.rate_tolerance > 0.0 && options_.rate_tolerance < 1.0))
    throw std::invalid_argument("time base: rate_tolerance must be in (0, 1)");
  if (!(options_.max_step > 0.0) || !std::isfinite(options_.max_step))
    throw std::invalid_argument("time base: max_step must be finite and > 0");
  if (!(options_.window > 0.0) || !std::isfinite(options_.window))
    throw std::invalid_argument("time base: window must be finite and > 0");
  if (!(options_.latency_slack >= 0.0) || !std::isfinite(options_.latency_slack))
    throw std::invalid_argument("time base: latency_slack must be finite and >= 0");
  if (!(options_.min_step > 0.0) || !std::isfinite(options_.min_step))
    throw std::invalid_argument("time base: min_step must be finite and > 0");
}

void TimeBase::restart() {
  have_history_ = false;
  trusted_ = false;
  good_run_ = 0;
  rate_checked_ = false;
}

void TimeBase::restart_history(double device_time) {
  have_history_ = true;
  start_device_ = device_time;
  newest_block_ = 0;
  good_run_ = 0;
  rate_checked_ = false;
  for (Block& b : blocks_) b.index = -1;
}

bool TimeBase::min_over(std::int64_t from, std::int64_t to, double& out) const {
  bool any = false;
  for (std::int64_t k = std::max<std::int64_t>(from, 0); k <= to; ++k) {
    const Block& b = blocks_[static_cast<std::size_t>(k % kRing)];
    if (b.index != k) continue;
    out = any ? std::min(out, b.min_d) : b.min_d;
    any = true;
  }
  return any;
}

std::optional<bool> TimeBase::rate_agrees(std::int64_t newest_block) const {
  const std::int64_t complete = newest_block;  // blocks 0 .. newest-1 are complete
  if (complete < kBlocksPerWindow) return std::nullopt;  // not enough history to judge yet
  const std::int64_t m = std::min<std::int64_t>(kBlocksPerWindow, complete / 2);
  double m_new = 0.0, m_old = 0.0;
  if (!min_over(newest_block - m, newest_block - 1, m_new)) return std::nullopt;
  if (!min_over(newest_block - 2 * m, newest_block - m - 1, m_old)) return std::nullopt;
  const double span = static_cast<double>(m) * block_length_;
  return std::abs(m_new - m_old) <= options_.rate_tolerance * span + options_.latency_slack;
}

TimeStamp TimeBase::finish(double candidate, bool device_trusted) {
  if (candidate < last_time_ + options_.min_step) {
    candidate = last_time_ + options_.min_step;
    ++counters_.nudged;
  }
  last_time_ = candidate;
  if (device_trusted)
    ++counters_.device_samples;
  else
    ++counters_.receive_samples;
  return TimeStamp{candidate, device_trusted};
}

TimeStamp TimeBase::update(double r, std::optional<double> device_time) {
  if (source_ == TimeSource::Receive || !device_time || !std::isfinite(*device_time)) return finish(r, false);
  const double s = *device_time;
  const double d = r - s;
  const bool auto_mode = source_ == TimeSource::Auto;

  // 2. Continuity: back, a step beyond max_step, or ahead of every least-delayed sample.
  bool violation = false;
  const double previous_s = last_device_;
  std::int64_t block = 0;
  if (have_history_) {
    if (!(s > last_device_)) {
      ++counters_.went_back;
      violation = true;
    } else if (s - last_device_ > options_.max_step) {
      ++counters_.jumps;
      violation = true;
    } else {
      block = static_cast<std::int64_t>(std::floor((s - start_device_) / block_length_));
      double envelope = 0.0;
      if (min_over(block - (kBlocksPerWindow - 1), block, envelope) &&
          d < envelope - (options_.rate_tolerance * options_.window + options_.latency_slack)) {
        ++counters_.jumps;  // the device clock leapt ahead of the receive clock
        violation = true;
      }
    }
  }
  // A continuing clock run: the previous device time is comparable with this one.
  bool continuous = have_history_ && !violation;

  // 3. History (a violation restarts it at this sample).
  if (!continuous) {
    restart_history(s);
    block = 0;
  }
  last_device_ = s;

  // 4. Rate check when this sample opens a new block.
  if (auto_mode && continuous && block > newest_block_) {
    const std::optional<bool> agrees = rate_agrees(block);
    if (agrees && !*agrees) {
      ++counters_.rate_disagreements;
      violation = true;
      continuous = false;
      restart_history(s);
      block = 0;
    } else if (agrees) {
      rate_checked_ = true;
    }
  }
  newest_block_ = std::max(newest_block_, block);
  Block& b = blocks_[static_cast<std::size_t>(block % kRing)];
  if (b.index != block) {
    b.index = block;
    b.min_d = d;
  } else {
    b.min_d = std::min(b.min_d, d);
  }
  ++good_run_;

  // 5. A violation ends the trust (auto); "device" re-anchors below.
  if (violation && trusted_ && auto_mode) {
    ++counters_.fallbacks;
    trusted_ = false;
  }

  // 7. The target offset: lower envelope over the current block and the 7 before it.
  double target = d;
  min_over(newest_block_ - (kBlocksPerWindow - 1), newest_block_, target);

  // 6. (Re)gaining trust.
  if (!trusted_) {
    const bool qualified = !auto_mode || (good_run_ >= options_.qualify_samples && rate_checked_);
    if (!qualified) return finish(r, false);
    trusted_ = true;
    ++counters_.qualifications;
    offset_ = target;
    if (continuous && std::isfinite(last_time_)) offset_ = std::max(target, last_time_ - previous_s);
  } else if (!continuous) {
    offset_ = target;  // "device": a new clock run starts at its receive time
  } else {
    const double limit = options_.rate_tolerance * (s - previous_s);
    offset_ = std::clamp(target, offset_ - limit, offset_ + limit);
  }
  return finish(s + offset_, true);
}

}  // namespace posefair::drivers
