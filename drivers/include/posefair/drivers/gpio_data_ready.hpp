#pragma once
// A data-ready (or sync) GPIO input line attached to any stream (docs/hid-gpio.md, "GPIO"):
// GpioDataReadySink sits between a stream's driver and its sink. For every sample pushed it
// drains the line's pending edge events (non-blocking, libgpiod 1.6) into an EdgePairer
// (gpio_edge_pairing.hpp), pairs the sample and forwards it, its time set to the edge's
// kernel timestamp when paired.
//
// Clocks: the GPIO character device's (v1 ABI, which libgpiod 1.6 uses) edge timestamps are
// CLOCK_MONOTONIC since Linux 5.7 (CLOCK_REALTIME before), the clock of Sample::receive_time.
// On an older kernel the sink never requests the line: its samples keep their times and it
// says why once.
//
// The line is requested lazily from push() (the driver's thread), so a missing chip, a line
// held by another consumer (EBUSY) or a chip that goes away never stops the stream: samples
// pass unpaired, the failure is logged once per reason, and the request is retried with the
// reconnect backoff (reconnect_backoff.hpp: reconnect_min doubling to reconnect_max) on later
// pushes. Nothing here runs on the engine or publisher threads.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>

#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/gpio_edge_pairing.hpp"
#include "posefair/drivers/driver_log.hpp"
#include "posefair/drivers/reconnect_backoff.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace posefair::drivers {

enum class GpioEdge { Rising, Falling };
enum class GpioBias { AsIs, PullUp, PullDown, Disabled };

// A line of a chip: by offset or by name (GPIO line names need not be unique: the first wins).
struct GpioLineRef {
  std::optional<unsigned> offset;
  std::string name;  // used when offset is empty
  std::string describe() const;
};

// An open chip and one requested line, released on destruction. Shared by the input and the
// output line.
class GpioLineHandle {
 public:
  GpioLineHandle() = default;
  ~GpioLineHandle() { release(); }
  GpioLineHandle(const GpioLineHandle&) = delete;
  GpioLineHandle& operator=(const GpioLineHandle&) = delete;

  // Opens `chip` (name "gpiochip0", path, label or number: gpiod_chip_open_lookup) and finds
  // the line; the caller requests it through line(). "" on success, else why not.
  std::string open(const std::string& chip, const GpioLineRef& ref);
  void release();
  gpiod_line* line() const { return line_; }
  bool is_open() const { return line_ != nullptr; }
  // After a request failed with EBUSY: " (held by '<consumer>')", for the log line.
  std::string held_by() const;

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* line_ = nullptr;
};

// reconnect_min, reconnect_max: the backoff between requests of the line (ReconnectSettings;
// the daemon's [stream.gpio] defaults are 0.1 s and 2 s).
struct GpioDataReadyOptions : ReconnectSettings {
  std::string chip;
  GpioLineRef line;
  GpioEdge edge = GpioEdge::Rising;
  GpioBias bias = GpioBias::AsIs;
  EdgePairingOptions pairing;
  std::string consumer = "posefaird";
  DriverLog log;           // may be empty; called from the driver's thread
};

// For the daemon's counter lines and STATUS=.
struct GpioDataReadyCounters {
  EdgePairingCounters pairing;
  bool line_held = false;
  std::uint64_t request_failures = 0;  // failed request attempts
  std::uint64_t losses = 0;            // line lost while held (read error: the chip went away)
};

class GpioDataReadySink final : public SampleSink {
 public:
  // Throws std::invalid_argument for bad tolerances or backoff. Touches no hardware.
  GpioDataReadySink(GpioDataReadyOptions options, SampleSink& next);
  ~GpioDataReadySink() override;

  // Driver thread.
  bool push(const Sample& sample) override;
  // Gives the line back (the driver has stopped); a later push requests it again.
  void release();
  // Drains the edges the kernel has queued into the pairer now and returns how many wait to be
  // paired (driver thread; tests use it to wait for an edge without pairing anything).
  std::size_t take_edges();

  // Any thread.
  GpioDataReadyCounters counters() const;
  std::string describe() const;  // "gpiochip0 line 17 (rising)"

 private:
  void try_request(double now);
  bool drain();  // false: the line was lost

  GpioDataReadyOptions options_;
  SampleSink& next_;
  EdgePairer pairer_;
  GpioLineHandle handle_;
  int fd_ = -1;
  bool clock_ok_ = true;
  double next_attempt_ = 0.0;
  ReconnectBackoff backoff_;
  std::string logged_reason_;
  std::uint64_t attempts_ = 0;

  std::atomic<bool> held_{false};
  std::atomic<std::uint64_t> request_failures_{0}, losses_{0};
  mutable std::mutex snapshot_mutex_;
  EdgePairingCounters snapshot_;
};

// CLOCK_MONOTONIC edge timestamps: Linux >= 5.7 (from `release`, e.g. "6.1.0-57-amd64").
bool gpio_event_clock_is_monotonic(const std::string& kernel_release);

}  // namespace posefair::drivers
