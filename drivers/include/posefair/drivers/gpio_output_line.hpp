#pragma once
// An optional GPIO output line for latency measurement with a scope (docs/hid-gpio.md): it
// toggles once per published pose of its stream (on_pose(), called by the daemon's publisher
// thread right after the pose was sent), or as a heartbeat at a fixed rate on its own thread.
//
// start() runs a small thread that requests the line (with the reconnect backoff,
// reconnect_backoff.hpp, while the chip is missing or the line busy) and, in heartbeat mode,
// toggles it. on_pose() is real-time safe: an atomic load and, once the line is held, one
// ioctl (gpiod_line_set_value: no allocation, no lock).
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "posefair/drivers/gpio_data_ready.hpp"

namespace posefair::drivers {

enum class GpioOutputMode { PerPose, Heartbeat };

// reconnect_min, reconnect_max: the backoff between requests of the line (ReconnectSettings;
// the daemon's [stream.gpio] defaults are 0.1 s and 2 s).
struct GpioOutputOptions : ReconnectSettings {
  std::string chip;
  GpioLineRef line;
  GpioOutputMode mode = GpioOutputMode::PerPose;
  double heartbeat_hz = 1.0;  // heartbeat mode: square wave of this frequency (two toggles per period)
  std::string consumer = "posefaird";
  DriverLog log;
};

struct GpioOutputCounters {
  bool line_held = false;
  std::uint64_t toggles = 0;
  std::uint64_t errors = 0;  // failed writes
};

class GpioOutputLine {
 public:
  // Throws std::invalid_argument for a bad rate or backoff. Touches no hardware.
  explicit GpioOutputLine(GpioOutputOptions options);
  ~GpioOutputLine();
  GpioOutputLine(const GpioOutputLine&) = delete;
  GpioOutputLine& operator=(const GpioOutputLine&) = delete;

  void start();
  void stop();  // joins the thread and releases the line; idempotent
  // Publisher thread, per published pose; does nothing in heartbeat mode or while not held.
  void on_pose() {
    if (options_.mode == GpioOutputMode::PerPose && held_.load(std::memory_order_acquire)) toggle();
  }
  GpioOutputCounters counters() const;
  std::string describe() const;

 private:
  void run(std::stop_token stop);
  void toggle();

  GpioOutputOptions options_;
  GpioLineHandle handle_;  // set up by the thread before held_ is published
  int value_ = 0;          // written by the one thread that toggles (publisher or heartbeat)
  std::atomic<bool> held_{false};
  std::atomic<std::uint64_t> toggles_{0}, errors_{0};
  std::jthread thread_;
};

}  // namespace posefair::drivers
