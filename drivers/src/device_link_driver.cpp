// The link supervision of the device drivers; see device_link_driver.hpp.
#include "posefair/drivers/device_link_driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <stdexcept>
#include <utility>

#include "link_log_text.hpp"
#include "monotonic_clock.hpp"
#include "sample_stamper.hpp"

namespace posefair::drivers {
namespace {

// Consecutive transient read errors after which the device is treated as gone and reopened.
constexpr int kTransientLimit = 10;
// A connection that lasted this long (s) resets the backoff when it is lost.
constexpr double kStableConnection = 1.0;

}  // namespace

DeviceLinkDriver::DeviceLinkDriver(std::string_view kind, const DeviceLinkOptions& options) : link_(options) {
  validate(static_cast<const ReconnectSettings&>(link_), kind);
  if (!(link_.read_timeout > 0.0 && link_.read_timeout <= 0.05))
    throw std::invalid_argument(std::string(kind) + ": read_timeout must be in (0, 0.05] s");
  const TimeBase check(link_.time_source, link_.time_base);  // throws for bad time base options
}

void DeviceLinkDriver::log(LogLevel level, const std::string& message) const {
  if (link_.log) link_.log(level, message);
}

DecoderCounters DeviceLinkDriver::decoder_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return decoder_snapshot_;
}

TimeBaseCounters DeviceLinkDriver::time_base_counters() const {
  std::lock_guard lock(snapshot_mutex_);
  return time_base_snapshot_;
}

std::string DeviceLinkDriver::device_path() const {
  std::lock_guard lock(snapshot_mutex_);
  return device_path_;
}

std::optional<DeviceHealth> DeviceLinkDriver::health() const {
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

void DeviceLinkDriver::publish_snapshots(const TimeBase& time_base) {
  {
    std::lock_guard lock(snapshot_mutex_);
    decoder_snapshot_ = link_decoder_counters();
    time_base_snapshot_ = time_base.counters();
  }
  fallbacks_.store(time_base.counters().fallbacks, std::memory_order_relaxed);
  trusted_.store(time_base.trusted(), std::memory_order_relaxed);
}

void DeviceLinkDriver::run(std::stop_token stop, SampleSink& sink) {
  using Clock = std::chrono::steady_clock;
  std::mutex wait_mutex;
  std::condition_variable_any wake;  // nobody notifies it: it wakes at the deadline or on stop
  auto wait = [&](double seconds) {
    std::unique_lock lock(wait_mutex);
    wake.wait_for(lock, stop, std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)),
                  [] { return false; });
  };

  const int timeout_ms = std::max(1, static_cast<int>(std::lround(link_.read_timeout * 1000.0)));
  TimeBase time_base(link_.time_source, link_.time_base);
  std::uint64_t sequence = 0;
  SampleStamper stamper(link_.stream_id, time_base, sink, sequence, samples_, dropped_);
  ReconnectBackoff backoff(link_);
  const std::string backoff_words = backoff.describe();

  bool open = false;
  bool lost = false;                           // an outage is in progress (the device was open before)
  double waiting_since = monotonic_seconds();  // since the first open attempt or the loss
  std::uint64_t attempts = 0;                  // failed opens since waiting_since
  unsigned logged_reasons = 0;                 // bit per LinkOpenFailure::reason logged in this wait
  std::string logged_note;
  int transient_streak = 0;
  double opened_at = 0.0;

  // The device is gone (or keeps failing): close, forget the partial frame, reconnect.
  auto lose = [&](const std::string& why) {
    close_link();
    open = false;
    connected_.store(false, std::memory_order_release);
    outages_.fetch_add(1, std::memory_order_relaxed);
    publish_snapshots(time_base);
    log(LogLevel::Warn, "lost " + lost_link_text() + " (" + why + "); reconnecting with backoff " + backoff_words);
    lost = true;
    waiting_since = monotonic_seconds();
    attempts = 0;
    logged_reasons = 0;
    transient_streak = 0;
    if (waiting_since - opened_at >= kStableConnection) {
      backoff.reset();
    } else {
      wait(backoff.next());  // a device that opens and fails at once: keep backing off instead of spinning
    }
  };

  while (!stop.stop_requested()) {
    if (!open) {
      std::variant<LinkOpened, LinkOpenFailure> result = open_link();
      if (const LinkOpenFailure* e = std::get_if<LinkOpenFailure>(&result)) {
        open_failures_.fetch_add(1, std::memory_order_relaxed);
        ++attempts;
        const unsigned bit = 1u << e->reason;
        // One line per reason per wait, not per retry; after a loss the loss line said "absent".
        if ((logged_reasons & bit) == 0 && !(lost && e->absent)) {
          logged_reasons |= bit;
          log(e->absent ? LogLevel::Warn : LogLevel::Error, "cannot open" + (e->kind.empty() ? "" : " (" + e->kind + ")") +
                                                                ": " + e->message + "; retrying with backoff " + backoff_words);
        }
        wait(backoff.next());
        continue;
      }
      const LinkOpened& o = std::get<LinkOpened>(result);
      const double waited = monotonic_seconds() - waiting_since;
      {
        std::lock_guard lock(snapshot_mutex_);
        device_path_ = o.path;
      }
      if (lost) {
        reconnects_.fetch_add(1, std::memory_order_relaxed);
        log(LogLevel::Info, "reopened " + o.where + " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1));
      } else {
        std::string line = "opened " + o.where + o.details;
        if (attempts > 0) line += " after " + seconds_text(waited) + " and " + attempts_text(attempts + 1);
        log(LogLevel::Info, line);
      }
      if (!o.note.empty() && o.note != logged_note) {
        log(LogLevel::Warn, o.note);
        logged_note = o.note;
      }
      open = true;
      lost = false;
      attempts = 0;
      opened_at = monotonic_seconds();
      logged_reasons = 0;
      transient_streak = 0;
      time_base.restart();
      connected_.store(true, std::memory_order_release);
      continue;
    }

    const LinkRead r = read_link(timeout_ms, stamper);
    if (r.decoded) {
      transient_streak = 0;
      publish_snapshots(time_base);
    }
    if (r.error == LinkRead::Error::None) continue;  // data, or a timeout: look at the stop token again
    if (r.error == LinkRead::Error::Gone) {
      lose(r.message);
      continue;
    }
    read_errors_.fetch_add(1, std::memory_order_relaxed);
    if (transient_streak++ == 0) log(LogLevel::Warn, "read error: " + r.message);
    if (transient_streak < kTransientLimit) {
      wait(link_.read_timeout);
      continue;
    }
    lose("repeated read errors: " + r.message);
  }
  close_link();
  connected_.store(false, std::memory_order_release);
}

}  // namespace posefair::drivers
