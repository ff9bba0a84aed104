#pragma once
// When a faired pose's sample was taken, on its stream's clock, from the pose's stamp and its
// sampled step (FairedPose::step, SampleGate::sampled_step).
//
// Samples read together (a serial adapter's latency timer, a USB or BLE packet of several
// reports) are stamped microseconds apart and then not at all for the rest of the read; their
// sampled steps are one interval each. Anything that places poses in time (a spline through
// them, a rate limit) needs when they were taken, not the stamps: a spline through knots 1 µs
// apart turns a 0.01 rad step into 10⁴ rad/s. The clock advances by the sampled step but never
// past the stamp, since a sample is not taken after it was received: the newest sample of a
// clump lands on its stamp and those before it an interval apart behind it. An evenly or
// jitterily stamped stream keeps its stamps (its sampled steps are its stamped ones). The times
// increase strictly while the stamps do.
#include <algorithm>

namespace posefair {

// Stamps closer than this are a clump's: the drivers stamp the samples of one read 1 µs apart
// (drivers' TimeBase, min_step), and no stream is sampled at 50 kHz. Until the stream's rate is
// known that is all that tells a clump (SampleGate's sampled steps are the stamped ones).
inline constexpr double kClumpStampStep = 20e-6;

class SampledClock {
 public:
  // stamp: the pose's time; step: its sampled step (0, a stream's first: the stamp).
  double next(double stamp, double step) {
    time_ = have_ && step > 0.0 ? std::min(stamp, time_ + step) : stamp;
    have_ = true;
    return time_;
  }

 private:
  bool have_ = false;
  double time_ = 0.0;
};

}  // namespace posefair
