#pragma once
// The driver interface: every sample source (a serial tracker, a CAN bus, a HID device, a
// replayed recording) is a Driver that runs on its own thread and hands each sample to a
// SampleSink. Nothing downstream of the sink can tell which kind of driver produced a sample.
#include <cstdint>
#include <optional>
#include <stop_token>
#include <string_view>

#include "posefair/core/sample.hpp"

namespace posefair::drivers {

// Where a driver delivers samples (the daemon's per-stream ring buffers, a recorder, a test's
// vector). push() is called from the driver's thread only.
class SampleSink {
 public:
  virtual ~SampleSink() = default;
  // false: the sink dropped the sample (full); the driver counts it and carries on.
  virtual bool push(const Sample& sample) = 0;
};

// The state of a driver's device link, for the daemon's counter lines and STATUS=: what an
// operator needs to tell a cable from a protocol from a clock problem. Drivers without a device
// (replays, synthetic) have none.
struct DeviceHealth {
  bool connected = false;
  std::uint64_t outages = 0;          // device lost while open
  std::uint64_t reconnects = 0;       // reopened after an outage
  std::uint64_t open_failures = 0;    // failed open attempts
  std::uint64_t read_errors = 0;      // transient read failures
  std::uint64_t frames = 0;           // frames whose checksum matched
  std::uint64_t bad_frames = 0;       // failed checksum or impossible contents
  std::uint64_t resyncs = 0;          // times bytes were skipped to find a frame
  std::uint64_t skipped_bytes = 0;
  bool device_time_trusted = false;   // samples timed by the device clock (time_base.hpp)
  std::uint64_t time_fallbacks = 0;   // trusted device time given up after a violation
};

class Driver {
 public:
  virtual ~Driver() = default;
  // A short description for logs and counters, e.g. "replay:session.pflog".
  virtual std::string_view name() const = 0;
  // Produces samples into `sink` until the source ends or `stop` is requested; then returns.
  // A driver returns promptly (milliseconds) after a stop request, also while it waits for
  // its device or for the next sample's time.
  virtual void run(std::stop_token stop, SampleSink& sink) = 0;
  // A snapshot readable from any thread while run() goes on; nullopt for drivers without a device.
  virtual std::optional<DeviceHealth> health() const { return std::nullopt; }
};

}  // namespace posefair::drivers
