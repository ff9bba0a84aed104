#pragma once
// The engine's time (Sample::time) for a live device: its receive time, or its own clock when
// that clock has shown it can be trusted (docs/devices.md, "Timestamps"). Pure: fed
// (receive_time, device_time) per sample, no clock inside, so tests and replays give exactly the
// same answer.
//
// Why: receive times carry the transport's jitter (USB polling, FTDI latency timers, frames
// arriving in bursts, the scheduler), typically milliseconds; a device's sample clock is exact
// to microseconds but runs on its own epoch and may reset, jump or drift. The rule keeps the
// device clock's spacing and puts it on the CLOCK_MONOTONIC scale of the receive times.
//
// THE RULE (time source "auto"). Per sample, r = receive time (CLOCK_MONOTONIC s), s = device
// time (s, when the protocol carries one), d = r − s (its offset: clock difference + transport
// delay).
//  1. No device time: time = r. Device time is not trusted.
//  2. Continuity: s must be after the previous device time, by at most `max_step` (1 s), and d
//     must not fall below the current envelope T (step 7) by more than rate_tolerance · window
//     + latency_slack (45 ms): a delay can only make d larger, so a d that much smaller means
//     the device clock leapt ahead. A sample that goes back (or repeats), steps too far or
//     leaps ahead is a violation (counted as went_back or jumps).
//  3. History: d is kept as minima per block of `window`/8 device seconds (0.25 s), blocks
//     counted from the first sample since the last (re)start; 16 complete blocks are kept.
//  4. Rate check, each time a sample opens a new block, once at least 8 blocks (`window`, 2 s)
//     are complete: with M = min(8, complete / 2), m_new = min d over the last M complete
//     blocks, m_old = min d over the M before them. The least-delayed sample of each half
//     estimates the clock offset, so m_new − m_old ≈ (receive rate / device rate − 1) · M·b
//     whatever the delays in between. Violation if |m_new − m_old| > rate_tolerance · M·b +
//     latency_slack (±2 % + 5 ms), counted as rate_disagreements.
//  5. A violation restarts the history at the violating sample, and while trusted it ends
//     the trust: a fallback (counted), time = r again.
//  6. Trust is (re)gained once `qualify_samples` (20) consecutive samples passed step 2 and at
//     least one rate check passed since the last restart: at least 2 s of agreement.
//  7. While trusted: time = s + o. The target offset T = the lower envelope of d: the minimum
//     over the current block and the 7 before it (the last 1.75 .. 2 s); the least-delayed
//     sample estimates the transport latency best. o follows T, slewed: per sample it moves
//     towards T by at most rate_tolerance · (s − previous s), so the output clock runs within
//     ±2 % of the device clock and absorbs the envelope's small steps and a drift within the
//     tolerance. When trust starts, o = max(T, previous time − previous s): the output
//     continues from the previous (receive-timed) sample with the device's spacing, then slews
//     down to T. Only while o is above T (that entry slew, or after the envelope stepped
//     down) can a time be later than its receive time, by at most o − T.
//  8. Always: time is at least `min_step` (1 µs) after the previous sample's time; an earlier
//     value is moved there (counted as nudged). Samples decoded from one read share their
//     receive time; this keeps them in order for the engine, which drops repeated times.
//
// Consequences: with a clean device clock and jittery delivery, consecutive times are spaced
// exactly as the device spaced them (except during slews, within ±2 %); the output sits the
// least observed delay behind the receive times. A device clock that drifts against
// CLOCK_MONOTONIC by ε (|ε| within the tolerance) stays trusted; its times are spaced by the
// receive clock's measure (device spacing · (1 + ε)) and, when the device runs slow, lag up to
// ε · window behind the least-delayed receive time (the envelope is that old). A reset (time
// back to 0) or a jump falls back to receive times and re-qualifies after 2 s.
//
// Time source "device": device time is trusted from the first sample; no qualification, no rate
// check; a continuity violation only restarts the history (counted as went_back / jumps) and
// re-anchors o at that sample's d (its time is its receive time). Time source "receive": time = r always (step 8 still applies).
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

namespace posefair::drivers {

enum class TimeSource {
  Auto,     // device time once trusted (the rule above), else receive time
  Receive,  // receive time only
  Device,   // device time whenever the sample carries one, without qualification
};
// "auto", "receive", "device"; nullopt for anything else.
std::optional<TimeSource> parse_time_source(std::string_view text);
std::string_view to_string(TimeSource source);

struct TimeBaseOptions {
  std::uint32_t qualify_samples = 20;  // consecutive continuous samples needed for trust
  double rate_tolerance = 0.02;        // (0, 1): allowed rate disagreement, and the slew rate of o
  double max_step = 1.0;               // s: largest device time step that is not a jump
  double window = 2.0;                 // s: the envelope's window (8 blocks) and half the rate check's span
  double latency_slack = 0.005;        // s: how much the least delay may differ between two windows
  double min_step = 1e-6;              // s: the least spacing of output times
};

struct TimeBaseCounters {
  std::uint64_t device_samples = 0;      // timed by the trusted device clock
  std::uint64_t receive_samples = 0;     // timed by their receive time
  std::uint64_t qualifications = 0;      // times device time became trusted
  std::uint64_t fallbacks = 0;           // trusted -> receive time, after a violation
  std::uint64_t went_back = 0;           // violations: device time not after the previous one
  std::uint64_t jumps = 0;               // violations: device time step > max_step
  std::uint64_t rate_disagreements = 0;  // violations: the rate check failed
  std::uint64_t nudged = 0;              // times moved to previous time + min_step
  friend bool operator==(const TimeBaseCounters&, const TimeBaseCounters&) = default;
};

struct TimeStamp {
  double time = 0.0;           // for Sample::time
  bool device_trusted = false; // true: derived from the device clock
};

class TimeBase {
 public:
  // Throws std::invalid_argument for options out of range.
  explicit TimeBase(TimeSource source = TimeSource::Auto, const TimeBaseOptions& options = {});

  // One sample: its receive time and, if it carries one, its device time (both seconds).
  TimeStamp update(double receive_time, std::optional<double> device_time);

  // Forgets the device clock's history (the device was reopened and may have restarted):
  // trust must be regained, without counting a fallback. The previous output time is kept, so
  // times stay increasing.
  void restart();

  bool trusted() const { return trusted_; }
  // The applied offset o (time − device time) while trusted; NaN otherwise.
  double offset() const { return trusted_ ? offset_ : std::numeric_limits<double>::quiet_NaN(); }
  const TimeBaseCounters& counters() const { return counters_; }
  TimeSource source() const { return source_; }
  const TimeBaseOptions& options() const { return options_; }

 private:
  static constexpr int kBlocksPerWindow = 8;
  static constexpr int kRing = 32;  // ≥ 2 · kBlocksPerWindow + 1
  struct Block {
    std::int64_t index = -1;  // block number since the history started; -1 = unused
    double min_d = 0.0;
  };

  void restart_history(double device_time);
  // Min d over blocks [from, to] (inclusive) that hold samples; false when none does.
  bool min_over(std::int64_t from, std::int64_t to, double& out) const;
  // The rate check of step 4 for a sample opening block newest_block; nullopt: too little history.
  std::optional<bool> rate_agrees(std::int64_t newest_block) const;
  TimeStamp finish(double candidate, bool device_trusted);

  TimeSource source_;
  TimeBaseOptions options_;
  double block_length_;
  TimeBaseCounters counters_;

  bool have_history_ = false;
  double start_device_ = 0.0;  // device time the block numbering starts at
  double last_device_ = 0.0;   // previous device time (valid with have_history_)
  std::int64_t newest_block_ = 0;
  std::uint64_t good_run_ = 0;
  bool rate_checked_ = false;
  std::array<Block, kRing> blocks_{};

  bool trusted_ = false;
  double offset_ = 0.0;
  double last_time_ = -std::numeric_limits<double>::infinity();
};

}  // namespace posefair::drivers
