#pragma once
// Pairing the kernel timestamps of a data-ready (or sync) GPIO line's edges with the samples of
// a stream: a sample that was announced by an edge gets the edge's time, which is far closer to
// the moment the sensor sampled than the time its bytes were read. Pure: fed edge times and
// sample receive times (both CLOCK_MONOTONIC seconds), no clock, no I/O, no allocation.
// docs/hid-gpio.md states the rule for operators; the GPIO driver drains the line's pending
// edge events before it pairs each sample (see "Order of events" there).
//
// THE RULE. Per sample with receive time r, its window is [r − tolerance_max, r − tolerance_min].
//  1. Expire: pending edges older than (the latest r seen) − tolerance_max can belong to no
//     sample any more; they are dropped and counted as extra_edges.
//  2. Pair: of the pending edges inside the window, the latest is the sample's edge; the
//     sample's time is that edge's time. Pending edges older than it (several edges in one
//     window: a glitch or a second pulse) are dropped and counted as extra_edges.
//     Edges after the window stay pending for later samples.
//  3. Missing: with no pending edge in the window, the sample keeps its receive time and is
//     counted as missing.
//  4. Order: edges may be added out of order (they are kept sorted). An edge at or before the
//     last paired edge comes too late to be paired (its sample has gone): it is dropped and
//     counted as late_edges. An edge that is not finite is dropped as late too.
//  5. At most 64 edges are pending; adding one more drops the oldest (counted in overflow).
// The window must be narrower than the sample period (tolerance_max − tolerance_min < 1/rate),
// so that one edge per sample falls inside it.
#include <array>
#include <cstddef>
#include <cstdint>

namespace posefair::drivers {

struct EdgePairingOptions {
  double tolerance_min = 0.0;    // s: least delay from the edge to the sample's receive time
  double tolerance_max = 0.005;  // s: largest delay
};

struct EdgePairingCounters {
  std::uint64_t edges = 0;        // edges added
  std::uint64_t samples = 0;      // samples given to pair()
  std::uint64_t paired = 0;       // samples that got an edge's time
  std::uint64_t missing = 0;      // samples without an edge in their window (kept their receive time)
  std::uint64_t extra_edges = 0;  // edges dropped unpaired: a later edge in the same window, or expired
  std::uint64_t late_edges = 0;   // edges at or before the last paired edge (or not finite)
  std::uint64_t overflow = 0;     // edges dropped because 64 were pending
  friend bool operator==(const EdgePairingCounters&, const EdgePairingCounters&) = default;
};

struct PairedTime {
  double time = 0.0;    // the edge's time when paired, else the receive time
  bool paired = false;
};

class EdgePairer {
 public:
  static constexpr std::size_t kMaxPending = 64;

  // Throws std::invalid_argument unless 0 <= tolerance_min <= tolerance_max, both finite.
  explicit EdgePairer(const EdgePairingOptions& options = {});

  // A kernel edge timestamp (s).
  void add_edge(double time);
  // A sample received at `receive_time` (s): its time by the rule.
  PairedTime pair(double receive_time);
  // Forgets pending edges and the pairing history (the line or the device was reopened); the
  // counters are kept.
  void reset();

  std::size_t pending() const { return count_; }
  const EdgePairingCounters& counters() const { return counters_; }
  const EdgePairingOptions& options() const { return options_; }

 private:
  void drop_front(std::size_t n);

  EdgePairingOptions options_;
  EdgePairingCounters counters_;
  std::array<double, kMaxPending> edges_{};  // pending edges, ascending
  std::size_t count_ = 0;
  double last_paired_;
  double latest_receive_;
};

}  // namespace posefair::drivers
