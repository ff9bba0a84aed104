// The serial driver: port, decoder, time base and reconnection; see serial_driver.hpp.
#include "posefair/drivers/serial_driver.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <stdexcept>
#include <utility>
#include <vector>

#include "link_log_text.hpp"
#include "monotonic_clock.hpp"
#include "sample_stamper.hpp"

namespace posefair::drivers {
namespace {

std::unique_ptr<Decoder> take_decoder(SerialDriverOptions& o) {
  if (o.decoder) return std::move(o.decoder);
  std::unique_ptr<Decoder> d = make_decoder(o.protocol, o.decoder_options);  // may throw for a bad option
  if (!d) {
    std::string known;
    for (const std::string& p : decoder_protocols()) known += (known.empty() ? "" : ", ") + p;
    throw std::invalid_argument("unknown protocol '" + o.protocol + "' (known: " + (known.empty() ? "none" : known) + ")");
  }
  return d;
}

// Consecutive transient read errors after which the port is treated as gone and reopened.
constexpr int kTransientLimit = 10;
// A connection that lasted this long (s) resets the backoff when it is lost.
constexpr double kStableConnection = 1.0;

}  // namespace

SerialDriver::SerialDriver(SerialDriverOptions options) : options_(std::move(options)) {
  if (!options_.port.usb && options_.port.device.empty())
    throw std::invalid_argument("serial: give a device path or a USB id");
  validate(options_.settings);
  if (!(options_.reconnect_min > 0.0) || !std::isfinite(options_.reconnect_min))
    throw std::invalid_argument("serial: reconnect_min must be finite and > 0");
  if (!(options_.reconnect_max >= options_.reconnect_min) || !std::isfinite(options_.reconnect_max))
    throw std::invalid_argument("serial: reconnect_max must be finite and >= reconnect_min");
  if (!(options_.read_timeout > 0.0 && options_.read_timeout <= 0.05))
    throw std::invalid_argument("serial: read_timeout must be in (0, 0.05] s");
  if (options_.read_buffer == 0) throw std::invalid_argument("serial: read_buffer must be > 0");
  const TimeBase check(options_.time_source, options_.time_base);  // throws for bad time base options
  decoder_ = take_decoder(options_);
  name_ = options_.name.empty() ? "serial:" + options_.port.describe() : options_.name;
}

void SerialDriver::log(LogLevel level, const std::string& message) const {
  if (options_.log) options_.log(level, message);
}

DecoderCounters SerialDriver::decoder_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return decoder_snapshot_;
}

TimeBaseCounters SerialDriver::time_base_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return time_base_snapshot_;
}

std::optional<DeviceHealth> SerialDriver::health() const {
  DeviceHealth h;
  h.connected = connected();
  h.outages = outages();
  h.reconnects = reconnects();
  h.open_failures = open_failures();
  h.read_errors = read_errors();
  const DecoderCounters d = decoder_counters();
  h.frames = d.frames;
  h.bad_frames = d.bad_checksum + d.malformed;
  h.resyncs = d.resyncs;
  h.skipped_bytes = d.skipped_bytes;
  h.device_time_trusted = device_time_trusted();
  h.time_fallbacks = time_base_fallbacks();
  return h;
}

std::string SerialDriver::device_path() const {
  std::lock_guard lock(snapshot_mutex_);
  return device_path_;
}

void SerialDriver::publish_snapshots(const TimeBase& time_base) {
  {
    std::lock_guard lock(snapshot_mutex_);
    decoder_snapshot_ = decoder_->counters();
    time_base_snapshot_ = time_base.counters();
  }
  fallbacks_.store(time_base.counters().fallbacks, std::memory_order_relaxed);
  trusted_.store(time_base.trusted(), std::memory_order_relaxed);
}

void SerialDriver::run(std::stop_token stop, SampleSink& sink) {
  using Clock = std::chrono::steady_clock;
  std::mutex wait_mutex;
  std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop
  auto wait = [&](double seconds) {
    std::unique_lock lock(wait_mutex);
    wake.wait_for(lock, stop, std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)),
                  [] { return false; });
  };

  const int timeout_ms = std::max(1, static_cast<int>(std::lround(options_.read_timeout * 1000.0)));
  std::vector<std::uint8_t> buffer(options_.read_buffer);
  TimeBase time_base(options_.time_source, options_.time_base);
  std::uint64_t sequence = 0;
  SampleStamper stamper(options_.stream_id, time_base, sink, sequence, samples_, dropped_);
  SerialPort port;

  const std::string backoff = backoff_text(options_.reconnect_min) + " .. " + backoff_text(options_.reconnect_max);
  bool lost = false;                           // an outage is in progress (the device was open before)
  double waiting_since = monotonic_seconds();  // since the first open attempt or the loss
  std::uint64_t attempts = 0;                  // failed opens since waiting_since
  double delay = options_.reconnect_min;
  unsigned logged_kinds = 0;  // bit per SerialErrorKind: open failures already logged in this wait
  auto bit = [](SerialErrorKind k) { return 1u << static_cast<unsigned>(k); };
  std::string logged_note;
  int transient_streak = 0;
  double opened_at = 0.0;

  while (!stop.stop_requested()) {
    if (!port.is_open()) {
      const SerialError e = port.open(options_.port, options_.settings);
      if (e) {
        open_failures_.fetch_add(1, std::memory_order_relaxed);
        ++attempts;
        if ((logged_kinds & bit(e.kind)) == 0) {  // one line per reason per wait, not per retry
          logged_kinds |= bit(e.kind);
          log(e.kind == SerialErrorKind::NotFound ? LogLevel::Warn : LogLevel::Error,
              "cannot open (" + std::string(to_string(e.kind)) + "): " + e.message + "; retrying with backoff " + backoff);
        }
        wait(delay);
        delay = std::min(delay * 2.0, options_.reconnect_max);
        continue;
      }
      const double waited = monotonic_seconds() - waiting_since;
      {
        std::lock_guard lock(snapshot_mutex_);
        device_path_ = port.path();
      }
      const std::string where =
          port.path() == options_.port.device ? port.path() : options_.port.describe() + " -> " + port.path();
      if (lost) {
        reconnects_.fetch_add(1, std::memory_order_relaxed);
        log(LogLevel::Info, "reopened " + where + " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1));
      } else {
        std::string line = "opened " + where + " at " + describe(options_.settings) + ", protocol " +
                           std::string(decoder_->protocol()) + ", time source " + std::string(to_string(options_.time_source));
        if (attempts > 0) line += " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1);
        log(LogLevel::Info, line);
      }
      if (!port.note().empty() && port.note() != logged_note) {
        log(LogLevel::Warn, port.note());
        logged_note = port.note();
      }
      lost = false;
      attempts = 0;
      opened_at = monotonic_seconds();
      logged_kinds = 0;
      transient_streak = 0;
      decoder_->reset();
      time_base.restart();
      connected_.store(true, std::memory_order_release);
      continue;
    }

    const SerialPort::ReadResult r = port.read(buffer, timeout_ms);
    if (r.bytes > 0) {
      const double received = monotonic_seconds();
      transient_streak = 0;
      bytes_.fetch_add(r.bytes, std::memory_order_relaxed);
      stamper.set_receive_time(received);
      decoder_->feed(std::span<const std::uint8_t>(buffer.data(), r.bytes), stamper);
      publish_snapshots(time_base);
      continue;
    }
    if (!r.error) continue;  // timeout: look at the stop token again
    if (r.error.kind != SerialErrorKind::DeviceGone) {
      read_errors_.fetch_add(1, std::memory_order_relaxed);
      if (transient_streak++ == 0) log(LogLevel::Warn, "read error: " + r.error.message);
      if (transient_streak < kTransientLimit) {
        wait(options_.read_timeout);
        continue;
      }
    }
    // The device is gone (or keeps failing): close, forget the partial frame, reconnect.
    port.close();
    decoder_->reset();
    connected_.store(false, std::memory_order_release);
    outages_.fetch_add(1, std::memory_order_relaxed);
    publish_snapshots(time_base);
    log(LogLevel::Warn, "lost the device (" + r.error.message + "); reconnecting with backoff " + backoff);
    lost = true;
    waiting_since = monotonic_seconds();
    attempts = 0;
    logged_kinds = bit(SerialErrorKind::NotFound);  // expected after a loss: the line above said so
    transient_streak = 0;
    if (waiting_since - opened_at >= kStableConnection) {
      delay = options_.reconnect_min;
    } else {
      // A device that opens and fails at once: keep backing off instead of spinning.
      wait(delay);
      delay = std::min(delay * 2.0, options_.reconnect_max);
    }
  }
  port.close();
  connected_.store(false, std::memory_order_release);
}

}  // namespace posefair::drivers
