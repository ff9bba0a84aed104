#pragma once
// Per-stream runtime counters: written by the thread that owns each event (driver, engine,
// publisher, recorder) with relaxed atomics, read at any time by the main thread for logs,
// SIGUSR1 and systemd's STATUS=. Never reset while a pipeline runs; rates and interval
// percentiles come from differences of snapshots.
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/orientation_estimator.hpp"
#include "posefair/daemon/latency_histogram.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/gpio_data_ready.hpp"
#include "posefair/drivers/gpio_output_line.hpp"

namespace posefair::daemon {

struct StreamCounters {
  std::atomic<std::uint64_t> received{0};         // handed over by the driver
  std::atomic<std::uint64_t> rejected{0};         // refused by the engine's gate (NaN, zero, non-unit)
  std::atomic<std::uint64_t> out_of_order{0};     // dropped by the gate (repeated or older time)
  std::atomic<std::uint64_t> raw_unfused{0};      // raw-only samples (kNoOrientation) kept out of the engine: no fusion stage made an orientation
  std::atomic<std::uint64_t> emitted{0};          // poses the engine produced
  std::atomic<std::uint64_t> clamped{0};          // of which the ε projection moved
  std::atomic<std::uint64_t> outliers_held{0};     // lone outliers held at the prediction (outlier_guard.hpp)
  std::atomic<std::uint64_t> outliers_released{0}; // of those, released: the next sample showed a motion
  std::atomic<std::uint64_t> restarts{0};         // windows restarted after a gap or a change of rate
  std::atomic<std::uint64_t> rate_changes{0};     // of which for a change of the measured rate
  std::atomic<std::uint64_t> repeated{0};         // samples that repeated the measurement before, carried forward (repeated_measurements.hpp)
  std::atomic<std::uint64_t> interpolated{0};     // samples of a slerped stream, interpolated between its measurements' poses (slerped_measurements.hpp)
  std::atomic<std::uint64_t> lost{0};             // samples lost within a step, stood in for in the window (not a gap)
  std::atomic<std::uint64_t> bridged_gaps{0};     // input gaps filled on the spline ([stream.spline] bridge_gap)
  std::atomic<std::uint64_t> bridged_samples{0};  // samples made for them
  std::atomic<std::uint64_t> unbridged_gaps{0};   // gaps passed through: longer than max_gap, or ended by a read too long to wait
  std::atomic<std::uint64_t> resampled{0};        // grid poses made ([stream.spline] publish_rate_hz)
  std::atomic<std::uint64_t> lerp_fallbacks{0};   // intervals matrix-lerp refused (pi/2 or more), interpolated separately
  std::atomic<std::uint64_t> published{0};        // poses sent to at least one destination (or to none configured)
  std::atomic<std::uint64_t> send_failures{0};    // failed sends (one per destination)
  std::atomic<std::uint64_t> recorded{0};         // handed to the recorder's writer
  std::atomic<std::uint64_t> record_paused{0};     // discarded while `posefair ctl record stop` held
  std::atomic<std::uint64_t> record_refused{0};    // refused by the writer: its buffer full while writes fail (disk full)
  LatencyHistogram latency;                       // hand-over → last datagram of the pose sent
  // The engine's state (FairingWindow::state()): the rate and window it settled on, and what
  // its adaptation measured and chose. Written by the engine thread after each batch.
  struct Channel {
    std::atomic<bool> adaptive{false}, at_rest{false}, rest_averaged{false};
    std::atomic<double> noise{0.0}, motion{0.0}, smoothing{0.0}, cutoff_hz{0.0};
    std::atomic<double> noise_scale{1.0};
    std::atomic<double> rest_noise{0.0};
  };
  std::atomic<double> engine_rate_hz{0.0};
  std::atomic<int> engine_window{0};
  std::atomic<bool> engine_repeating{false};  // the stream repeats its measurements: the rate is its source's
  std::atomic<bool> engine_slerped{false};    // the stream is slerped from a slower source: the rate is its source's
  Channel rotation, position;
  // Gyro-aided fairing (EngineState::gyro): whether the window uses a gyro now, and its
  // estimated bias and time offset; with a gyro_stream, the samples that got a reading from it.
  struct Gyro {
    std::atomic<bool> active{false}, offset_estimated{false};
    std::atomic<double> bias_x{0.0}, bias_y{0.0}, bias_z{0.0};  // rad/s, gyro frame
    std::atomic<double> time_offset_s{0.0};
    std::atomic<std::uint64_t> intervals{0};
    std::atomic<std::uint64_t> matched{0}, unmatched{0};  // gyro_pairing.hpp
    std::atomic<std::uint64_t> bridged{0};  // missing readings bridged without a restart (WindowCounters)
  };
  Gyro gyro;
  // [stream.fusion]: the estimator's state and counters (EstimatorState), written by the
  // engine thread after each batch.
  struct Fusion {
    std::atomic<std::uint64_t> waiting{0};  // raw samples before the first accelerometer reading
    std::atomic<std::uint64_t> updates{0};  // samples the estimator took
    std::atomic<std::uint64_t> nonfinite{0}, gyro_saturated{0}, mag_stuck{0}, mag_absent{0}, bad_time_steps{0},
        gaps{0}, state_resets{0};
    std::atomic<bool> initialised{false}, at_rest{false}, mag_disturbed{false};
    std::atomic<double> bias_x{0.0}, bias_y{0.0}, bias_z{0.0};  // rad/s
  };
  Fusion fusion;
};

// [stream.engine] gyro_stream: the source stream's name and the samples that got a reading
// from it (matched) or none (unmatched: no reading of the source in their interval).
struct GyroPairingStats {
  std::string source;
  std::uint64_t matched = 0, unmatched = 0;
};

// A consistent-enough copy for reporting (each field read once, relaxed).
struct StreamStats {
  std::uint32_t id = 0;
  std::string name;
  std::string driver;
  bool driver_running = false;
  std::uint64_t received = 0, ring_dropped = 0, rejected = 0, out_of_order = 0, emitted = 0, clamped = 0, restarts = 0;
  std::uint64_t rate_changes = 0;  // of the restarts, for a change of the measured rate
  std::uint64_t repeated = 0;  // samples that repeated the measurement before, carried forward (repeated_measurements.hpp)
  std::uint64_t interpolated = 0;  // samples of a slerped stream, interpolated between its measurements' poses (slerped_measurements.hpp)
  std::uint64_t lost = 0;  // samples lost within a step (a lost packet), stood in for in the window (not a gap)
  std::uint64_t outliers_held = 0, outliers_released = 0;  // the outlier guard (outlier_guard.hpp)
  std::uint64_t gyro_bridged = 0;  // gyro readings missing from an aided window, bridged (no restart)
  std::uint64_t raw_unfused = 0;  // raw-only samples not faired (no orientation, no fusion stage); still recorded
  std::uint64_t publish_dropped = 0, published = 0, send_failures = 0, recorded = 0, record_dropped = 0;
  HistogramSnapshot latency;
  EngineState engine;      // rate, window, the adaptation's noise, motion and cutoff, and the gyro aiding's estimates
  bool bridging = false, resampling = false;  // [stream.spline] parts configured
  std::uint64_t bridged_gaps = 0, bridged_samples = 0, unbridged_gaps = 0, resampled = 0;
  bool matrix_lerp = false;  // [stream.spline] pose_interpolation = "matrix-lerp"
  std::uint64_t lerp_fallbacks = 0;
  std::optional<drivers::DeviceHealth> device;  // the device link, for drivers that have one
  std::optional<drivers::GpioDataReadyCounters> data_ready;  // [stream.gpio] data_ready_line
  std::optional<drivers::GpioOutputCounters> gpio_output;    // [stream.gpio] output_line
  std::optional<EstimatorState> fusion;                      // [stream.fusion]
  std::optional<GyroPairingStats> gyro_pairing;              // [stream.engine] gyro_stream
  std::uint64_t fusion_waiting = 0;                          // raw samples before its first accelerometer reading
  // Poses lost on the way to subscribers: overflow of the engine's and the publisher's rings.
  std::uint64_t dropped() const { return ring_dropped + publish_dropped; }
};

}  // namespace posefair::daemon
