// The scope output line on libgpiod 1.6; see gpio_output_line.hpp.
#include "posefair/drivers/gpio_output_line.hpp"

#include <gpiod.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "link_log_text.hpp"

namespace posefair::drivers {

GpioOutputLine::GpioOutputLine(GpioOutputOptions options) : options_(std::move(options)) {
  if (options_.chip.empty()) throw std::invalid_argument("GPIO output: no chip");
  if (!(options_.heartbeat_hz > 0.0) || !std::isfinite(options_.heartbeat_hz))
    throw std::invalid_argument("GPIO output: heartbeat_hz must be finite and > 0");
  validate(static_cast<const ReconnectSettings&>(options_), "GPIO output");
}

GpioOutputLine::~GpioOutputLine() { stop(); }

std::string GpioOutputLine::describe() const {
  return options_.chip + " " + options_.line.describe() +
         (options_.mode == GpioOutputMode::PerPose ? " (per pose)" : " (heartbeat)");
}

void GpioOutputLine::start() {
  if (thread_.joinable()) return;
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void GpioOutputLine::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  held_.store(false, std::memory_order_release);
  handle_.release();
}

void GpioOutputLine::toggle() {
  value_ ^= 1;
  if (::gpiod_line_set_value(handle_.line(), value_) == 0)
    toggles_.fetch_add(1, std::memory_order_relaxed);
  else
    errors_.fetch_add(1, std::memory_order_relaxed);
}

void GpioOutputLine::run(std::stop_token stop) {
  using Clock = std::chrono::steady_clock;
  std::mutex m;
  std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop
  auto wait_until = [&](Clock::time_point t) {
    std::unique_lock lock(m);
    wake.wait_until(lock, stop, t, [] { return false; });
  };
  auto log = [&](LogLevel l, const std::string& s) {
    if (options_.log) options_.log(l, s);
  };

  ReconnectBackoff backoff(options_);
  std::string logged;
  std::uint64_t attempts = 0;
  while (!stop.stop_requested()) {
    std::string why = handle_.open(options_.chip, options_.line);
    if (why.empty() && ::gpiod_line_request_output(handle_.line(), options_.consumer.c_str(), 0) != 0) {
      const int e = errno;
      why = "cannot request GPIO output " + describe() + ": " + std::strerror(e);
      if (e == EBUSY) why += handle_.held_by();
    }
    if (why.empty()) break;
    handle_.release();
    ++attempts;
    if (why != logged) {
      log(LogLevel::Warn, why + "; retrying with backoff " + backoff.describe());
      logged = why;
    }
    wait_until(Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(backoff.next())));
  }
  if (stop.stop_requested()) return;
  value_ = 0;
  held_.store(true, std::memory_order_release);
  log(LogLevel::Info, "took GPIO output " + describe() + (attempts > 0 ? " after " + attempts_text(attempts + 1) : std::string()));
  if (options_.mode != GpioOutputMode::Heartbeat) return;  // the publisher toggles it
  // A square wave of heartbeat_hz (what a scope shows): two toggles per period.
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(0.5 / options_.heartbeat_hz));
  Clock::time_point next = Clock::now();
  while (!stop.stop_requested()) {
    toggle();
    next += period;
    wait_until(next);
  }
}

GpioOutputCounters GpioOutputLine::counters() const {
  GpioOutputCounters c;
  c.line_held = held_.load(std::memory_order_acquire);
  c.toggles = toggles_.load(std::memory_order_relaxed);
  c.errors = errors_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace posefair::drivers
