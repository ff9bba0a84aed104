#include "posefair/core/sample_gate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "posefair/core/engine_setting.hpp"

namespace posefair {

SampleGate::SampleGate(const GateConfig& config) : config_(config) {
  if (!(config.unit_tolerance >= 0.0 && config.unit_tolerance < 1.0))
    throw InvalidEngineSetting(EngineSetting::UnitTolerance, "unit_tolerance must be in [0, 1)");
  if (!(config.gap_threshold > 0.0))
    throw InvalidEngineSetting(EngineSetting::GapThreshold, "gap_threshold must be positive");
  if (!(config.gap_intervals == 0.0 || (config.gap_intervals >= 1.5 && config.gap_intervals <= 1e6)))
    throw InvalidEngineSetting(EngineSetting::GapThreshold, "gap_intervals must be 0 (off) or in [1.5, 1e6]");
}

void SampleGate::set_interval(double interval) {
  interval_ = config_.gap_intervals > 0.0 && interval > 0.0 ? interval : 0.0;
  ahead_ = 0.0;
}

GateVerdict SampleGate::validity(const Sample& s) const {
  const bool finite = std::isfinite(s.time) && s.orientation.coeffs().allFinite() &&
                      (!s.has_position() || s.position.allFinite());
  if (!finite) return GateVerdict::RejectNonFinite;
  const double norm = s.orientation.norm();
  if (norm == 0.0) return GateVerdict::RejectZero;
  if (std::abs(norm - 1.0) > config_.unit_tolerance) return GateVerdict::RejectNonUnit;
  return GateVerdict::Accept;
}

GateVerdict SampleGate::check(Sample& s) {
  switch (const GateVerdict v = validity(s)) {
    case GateVerdict::RejectNonFinite:
      ++counters_.rejected_non_finite;
      return v;
    case GateVerdict::RejectZero:
      ++counters_.rejected_zero;
      return v;
    case GateVerdict::RejectNonUnit:
      ++counters_.rejected_non_unit;
      return v;
    default:
      break;
  }
  const double norm = s.orientation.norm();
  if (s.time == last_time_) {
    ++counters_.dropped_repeated;
    return GateVerdict::DropRepeated;
  }
  if (s.time < last_time_) {
    ++counters_.dropped_out_of_order;
    return GateVerdict::DropOutOfOrder;
  }
  if (norm != 1.0) {
    s.orientation.coeffs() /= norm;
    ++counters_.renormalised;
  }
  bool gap = false;
  sampled_step_ = 0.0;
  if (std::isfinite(last_time_)) {
    const double step = s.time - last_time_;
    gap = step > config_.gap_threshold || (interval_ > 0.0 && step - ahead_ > config_.gap_intervals * interval_);
    // Inside a clump (a step under half the interval) or catching up after one, a sample was
    // taken an interval after the last, or what the step takes beyond the catching up.
    const bool clumped = interval_ > 0.0 && (step < 0.5 * interval_ || ahead_ > 0.5 * interval_);
    sampled_step_ = gap || !clumped ? step : std::max(interval_, step - ahead_);
    // A clump runs ahead of one sample per interval; the steps after it catch up. 5 % of the
    // time that passes is forgiven, so a burst of stale samples at start-up, or a rate measured
    // a little high, does not hide the gaps after it for long.
    ahead_ = gap ? 0.0 : std::clamp(ahead_ + interval_ - 1.05 * step, 0.0, config_.gap_threshold);
  }
  last_time_ = s.time;
  ++counters_.accepted;
  if (gap) {
    ++counters_.gaps;
    return GateVerdict::AcceptAfterGap;
  }
  return GateVerdict::Accept;
}

}  // namespace posefair
