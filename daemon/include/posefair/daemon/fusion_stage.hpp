#pragma once
// [stream.fusion] (docs/fusion.md): on the engine thread, before the fairing engine, a raw
// inertial sample (kNoOrientation) gets its orientation from the stream's orientation
// estimator (core/…/orientation_estimator.hpp, built by name from the registry). Samples that
// already carry an orientation pass unchanged. Built once at pipeline construction; apply()
// does not allocate.
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

#include "posefair/core/orientation_estimator.hpp"
#include "posefair/core/sample.hpp"
#include "posefair/daemon/config.hpp"

namespace posefair::daemon {

class FusionStage {
 public:
  // Throws what the estimator's factory throws (the config loader has already judged the options).
  explicit FusionStage(const FusionConfig& config)
      : estimator_(make_orientation_estimator(config.estimator, config.options)) {}

  // True when `s` goes on to the engine: it carried an orientation, or it was raw and now has
  // the estimate. False for a raw sample before the estimator's first accelerometer reading
  // (counted in waiting()): there is no orientation to give it yet.
  bool apply(Sample& s) {
    if (s.has_orientation()) return true;
    const double dt = std::isnan(last_time_) ? 0.0 : s.time - last_time_;
    last_time_ = s.time;
    estimator_->update(s, dt);
    if (!estimator_->state().initialised) {
      ++waiting_;
      return false;
    }
    s.orientation = estimator_->orientation();
    s.flags &= ~static_cast<std::uint32_t>(kNoOrientation);
    return true;
  }

  const EstimatorState& state() const { return estimator_->state(); }
  std::uint64_t waiting() const { return waiting_; }

 private:
  std::unique_ptr<OrientationEstimator> estimator_;
  double last_time_ = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t waiting_ = 0;
};

}  // namespace posefair::daemon
