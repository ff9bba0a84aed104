#pragma once
// The streams of `posefair bench streams` (docs/benchmarks.md, "Generated streams"): motions
// that no default or grid was chosen on, each sampled at rates from 10 Hz to 1 kHz with three
// noise levels, so that the defaults can be judged on streams unlike the benchmark's data sets.
//   still   a tracker lying still
//   sway    slow wandering, three sines of 0.2–0.8 Hz about the three axes (0.4 rad each)
//   turns   a head in VR: still for 0.5–2 s, then turned 30–120° in 0.15–0.4 s, and so on
//   shake   sway plus a tremor of 0.02 rad at 5–9 Hz (above Nyquist at 10 Hz: aliased)
//   walk    a handheld camera: angular velocity an Ornstein–Uhlenbeck process (0.5 rad/s RMS,
//           correlation time 0.3 s), integrated
// Noise as the quality benchmark's synthetic sets: exp(δ), ‖δ‖ uniform below the bound (dist on
// S³). Deterministic: the seed is the stream's name. The truth is sampled 8 times as densely
// (at least 2 kHz), so it can be looked up between samples.
// Resampled: measured at a lower source rate and delivered at the stream's rate, as a tracker
// polled faster than it updates ("hold": the newest measurement again) or a log put on another
// clock ("linear": slerp between the two measurements around each time; BROAD's optical stream
// is a 240 Hz one put on its IMU's 285.7 Hz clock so).
#include <string>
#include <vector>

#include "quality_datasets.hpp"

namespace posefair::tools {

struct GeneratedStreamSpec {
  std::string motion;  // still, sway, turns, shake, walk
  double rate_hz = 100.0;
  double noise = 0.01;  // bound on ‖δ‖ (rad)
  double seconds = 20.0;
  double source_hz = 0.0;   // resampled from this rate (0: measured at rate_hz)
  std::string resampling;   // hold, linear (with source_hz)
  // Runs of 4 to 12 samples lost, this many a second on average (a radio tracker's dropped
  // packets; each run is a gap that restarts the window): 0, none.
  double dropouts_per_s = 0.0;
  // One or two samples lost, this many times a second on average (a radio tracker's lost
  // packets; each a step of two or three intervals, no gap): 0, none.
  double lost_per_s = 0.0;
  // The noise this many times larger for one second in every five, from 3 s on (a marker half
  // hidden, a camera in low light; the same stream as without them, its noise scaled): 0, none.
  double burst_factor = 0.0;
  // "sway-100Hz-noise0.01", "sway-250Hz-noise0.01-from60Hz-hold", "turns-120Hz-noise0.01-dropouts",
  // "walk-60Hz-noise0.01-lost", "still-60Hz-noise0.002-bursts"
  std::string name() const;
};

// Every motion × rate (10, 30, 60, 120, 250, 1000 Hz) × noise (0.0002: a clean stream, as a good
// VR tracker's; 0.002, 0.01, 0.04), and still,
// sway, turns and walk measured at 60 Hz under noise 0.01, resampled to 250 Hz both ways, and at
// 120 Hz under noise 0.002 and 0.01 with dropouts (one a second), and at 60 Hz under the same with
// lost packets (five a second), and at 60 and 250 Hz under noise 0.002 with bursts of five times
// the noise; quick:
// sway and turns at 30 and 100 Hz, noise 0.01, 5 s.
std::vector<GeneratedStreamSpec> generated_stream_specs(bool quick);

// The stream, its truth, and its first second (warm-up) left out of scoring. Throws
// std::invalid_argument for a motion or resampling it does not know.
QualitySequence generated_stream(const GeneratedStreamSpec& spec);

}  // namespace posefair::tools
