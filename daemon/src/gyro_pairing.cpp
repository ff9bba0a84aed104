#include "posefair/daemon/gyro_pairing.hpp"

#include <algorithm>
#include <cmath>

namespace posefair::daemon {

static_assert((GyroPairing::kCapacity & (GyroPairing::kCapacity - 1)) == 0, "a power of two: indices wrap by mask");

GyroPairing::GyroPairing()
    : inbox_(std::make_unique<SpscRing<InboxReading>>(kCapacity, OverflowPolicy::DropOldest)), ring_(kCapacity) {}

void GyroPairing::add(double time, const Vec3& gyro) {
  if (!std::isfinite(time) || !gyro.allFinite()) return;
  inbox_->push(InboxReading{time, {gyro.x(), gyro.y(), gyro.z()}});
}

void GyroPairing::keep(double time, const Vec3& gyro) {
  if (count_ > 0 && !(time > ring_[(next_ - 1) & (kCapacity - 1)].time)) return;
  ring_[next_ & (kCapacity - 1)] = Reading{time, gyro};
  ++next_;
  count_ = std::min(count_ + 1, kCapacity);
}

void GyroPairing::apply(Sample& s) {
  for (InboxReading r; inbox_->pop(r);) keep(r.time, Vec3(r.gyro[0], r.gyro[1], r.gyro[2]));
  const double t = s.time;
  s.flags &= ~static_cast<std::uint32_t>(kHasGyro);
  // A repeated or older time (the engine's gate drops the sample) or a non-finite one (it
  // rejects it) is no interval.
  if (!std::isfinite(t) || (!std::isnan(last_time_) && !(t > last_time_))) return;
  double from = last_time_;
  last_time_ = t;
  // After a gap (an interval over twice the one before) the mean over the whole gap is no rate
  // at t: the sample takes one interval of the old length, and the line starts again.
  if (last_interval_ > 0.0 && t - from > 2.0 * last_interval_) {
    const double interval = t - from;
    from = t - last_interval_;
    last_interval_ = interval;
    have_previous_ = false;
  } else if (!std::isnan(from)) {
    last_interval_ = t - from;
  }
  std::size_t n = 0;
  Vec3 sum = Vec3::Zero();
  double time_sum = 0.0;
  if (!std::isnan(from)) {  // the first sample has no interval yet
    for (std::size_t i = 0; i < count_; ++i) {
      const Reading& r = ring_[(next_ - 1 - i) & (kCapacity - 1)];
      if (r.time > t) continue;  // the source is ahead: a later interval's reading
      if (r.time <= from) break;
      sum += r.gyro;
      time_sum += r.time;
      ++n;
    }
  }
  if (n == 0) {
    ++unmatched_;
    have_previous_ = false;
    return;
  }
  const double count = static_cast<double>(n);
  const Vec3 mean = sum / count;
  const double centre = time_sum / count;
  Vec3 rate = mean;
  if (have_previous_ && centre > previous_time_)
    rate += (mean - previous_mean_) * std::clamp((t - centre) / (centre - previous_time_), 0.0, 1.0);
  have_previous_ = true;
  previous_time_ = centre;
  previous_mean_ = mean;
  s.gyro = rate;
  s.flags |= kHasGyro;
  ++matched_;
}

}  // namespace posefair::daemon
