#pragma once
// How `posefair bench quality` scores an output stream (docs/benchmarks.md, "Metrics"), with the
// same lag accounting for every family: each pose carries the time it is for (its stamp) and
// the time it reaches the user (the arrival of the sample whose push emitted it, plus the
// measured processing time per sample).
//   (a) delivered: the error against truth at the delivery time, what a user sees;
//   (b) aligned:   the error at the best time alignment; its lag is the shift of that alignment
//                  measured from the delivery times, i.e. alignment shift + delivery delay.
// BROAD has no orientation truth: its smoothing error is the body rate from consecutive
// outputs against the gyroscope (rad/s), at the optical stream's own shift to the gyroscope;
// its prediction truth is the optical sample nearest t + h, carried to t + h by the gyroscope.
#include <span>
#include <vector>

#include "posefair/core/fairing_window.hpp"
#include "quality_datasets.hpp"

namespace posefair::tools {

struct DeliveredStream {
  std::vector<Quat> pose;         // one per input sample (the input where nothing was emitted)
  std::vector<double> stamp;      // the time each pose is for
  std::vector<double> delivered;  // the time it reaches the user
  double ns_per_sample = 0.0;
};

// A stream that passes each sample on as it comes (filters, raw): delivered at its own time
// plus processing.
DeliveredStream delivered_as_sampled(const PoseSequence& input, std::vector<Quat> pose, double ns_per_sample);

// The real-time engine over a sequence, sample by sample as fair_causal and the daemon run it,
// recording which push emitted each pose (the tail a flush emits is delivered at the last
// sample's time). gyro: none, or one reading per sample (rad/s), which the samples then carry
// (kHasGyro: gyro-aided fairing). final_state: the engine's state after the last push.
DeliveredStream run_engine(const PoseSequence& input, const WindowConfig& config, std::span<const Vec3> gyro = {},
                           EngineState* final_state = nullptr);

// The largest rotation angle between run_engine's poses and fair_causal's for the same input and
// configuration: the benchmark's rows must be what fair_causal gives.
double difference_to_fair_causal(const PoseSequence& input, const WindowConfig& config, const DeliveredStream& s);

struct SmoothingScore {
  double error_delivered = 0.0;  // (a): rad, or rad/s against the gyroscope (BROAD)
  double error_aligned = 0.0;    // (b)
  double lag_ms = 0.0;           // (b): alignment shift + delivery delay (bench quality then subtracts raw's on the same sequence)
  double delivery_ms = 0.0;      // mean delivery delay (delivered − stamp)
  double jitter = 0.0;           // RMS angular acceleration of the output (rad/s²)
  double relative_error = 0.0;   // RMS sample-to-sample rotation error at delivery times (rad; NaN for BROAD)
  double max_deviation = 0.0;    // rad, physical angle from the input
  double ns_per_sample = 0.0;
};

SmoothingScore score_smoothing(const QualitySequence& q, bool broad, const DeliveredStream& s);

struct PredictionScore {
  double error = 0.0;   // RMS rotation angle to truth at t + h (rad)
  double jitter = 0.0;  // RMS angular acceleration of the predicted stream (rad/s²)
};

// predicted[i]: the pose predicted from samples up to i for input.time[i] + horizon_s.
PredictionScore score_prediction(const QualitySequence& q, bool broad, const std::vector<Quat>& predicted, double horizon_s);

// BROAD: an upper bound on the noise of one optical sample (rad), the floor of its prediction
// truth: the raw stream's rate error against the gyroscope times the period, over √2 (the rate
// of consecutive samples carries two samples' noise; gyroscope noise is counted in it too).
double optical_noise_bound(const QualitySequence& q);

}  // namespace posefair::tools
