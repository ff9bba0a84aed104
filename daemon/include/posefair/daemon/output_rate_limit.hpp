#pragma once
// [[output]] max_rate_hz: at most that many poses a second per stream reach the output's
// clients (a VRChat or opentrack client wants ~60–120 Hz, not a 1 kHz tracker). A pose passes
// when at least 1/max_rate_hz of sample time has gone by since the last one that passed for its
// stream; the rest are skipped, not delayed, so the latency of what passes is unchanged.
#include <cstddef>
#include <limits>
#include <vector>

namespace posefair::daemon {

class OutputRateLimit {
 public:
  // max_rate_hz <= 0: every pose passes.
  OutputRateLimit(double max_rate_hz, std::size_t streams)
      : interval_(max_rate_hz > 0.0 ? 1.0 / max_rate_hz : 0.0),
        last_(interval_ > 0.0 ? streams : 0, -std::numeric_limits<double>::infinity()) {}

  bool admit(std::size_t stream_index, double time) {
    if (interval_ <= 0.0) return true;
    double& last = last_[stream_index];
    // A little slack for sample times that are a rate's multiple only up to rounding; a time
    // that went back (a restarted replay) starts the stream over.
    if (time >= last && time - last < interval_ * (1.0 - 1e-6)) return false;
    last = time;
    return true;
  }

 private:
  double interval_;
  std::vector<double> last_;  // per stream index: the sample time of the last pose passed
};

}  // namespace posefair::daemon
