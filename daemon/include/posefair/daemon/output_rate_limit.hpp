#pragma once
// [[output]] max_rate_hz: at most that many poses a second per stream reach the output's
// clients (a VRChat or opentrack client wants ~60–120 Hz, not a 1 kHz tracker). A pose passes
// when at least 1/max_rate_hz of sample time has gone by since the last one that passed for its
// stream; the rest are skipped, not delayed, so the latency of what passes is unchanged. Sample
// time is when the samples were taken (sampled_clock.hpp): of samples stamped in a clump, 1 µs
// apart, the stamps would pass only the first, the stalest, once per read.
#include <cstddef>
#include <limits>
#include <vector>

#include "posefair/core/sampled_clock.hpp"

namespace posefair::daemon {

class OutputRateLimit {
 public:
  // max_rate_hz <= 0: every pose passes.
  OutputRateLimit(double max_rate_hz, std::size_t streams)
      : interval_(max_rate_hz > 0.0 ? 1.0 / max_rate_hz : 0.0),
        last_(interval_ > 0.0 ? streams : 0, -std::numeric_limits<double>::infinity()),
        clocks_(interval_ > 0.0 ? streams : 0) {}

  // Every pose of a stream the output carries, in order: its stamp and FairedPose::step.
  bool admit(std::size_t stream_index, double stamp, double step) {
    if (interval_ <= 0.0) return true;
    const double time = clocks_[stream_index].next(stamp, step);
    double& last = last_[stream_index];
    // Sample times are a rate's multiple only up to rounding and jitter, and a clump's are
    // squeezed where they meet its stamp (with a rate measured a hair slow, the steps before
    // a read's last are a hair long, and the last one short by their excess): 1% slack, so a
    // 200 Hz stream limited to 100 passes every second pose, not every third. A time that went
    // back (a restarted replay) starts the stream over.
    if (time >= last && time - last < interval_ * (1.0 - kSlack)) return false;
    last = time;
    return true;
  }

 private:
  static constexpr double kSlack = 0.01;
  double interval_;
  std::vector<double> last_;  // per stream index: the sample time of the last pose passed
  std::vector<SampledClock> clocks_;
};

}  // namespace posefair::daemon
