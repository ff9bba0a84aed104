#pragma once
// The driver interface: every sample source (a serial tracker, a CAN bus, a HID device, a
// replayed recording) is a Driver that runs on its own thread and hands each sample to a
// SampleSink. Nothing downstream of the sink can tell which kind of driver produced a sample.
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

class Driver {
 public:
  virtual ~Driver() = default;
  // A short description for logs and counters, e.g. "replay:session.pflog".
  virtual std::string_view name() const = 0;
  // Produces samples into `sink` until the source ends or `stop` is requested; then returns.
  // A driver returns promptly (milliseconds) after a stop request, also while it waits for
  // its device or for the next sample's time.
  virtual void run(std::stop_token stop, SampleSink& sink) = 0;
};

}  // namespace posefair::drivers
