#pragma once
// The base of every driver with a device that can come and go (serial, SocketCAN, hidraw):
// it supervises the link, the driver behind it only opens, reads and closes its device.
//
// run() (final):
//   - opens the device through open_link(). While it is absent or refuses, it retries with the
//     reconnect backoff (reconnect_backoff.hpp: reconnect_min, doubling, up to reconnect_max).
//   - on each open restarts the time base (time_base.hpp) and marks the link connected; then
//     calls read_link() with a short timeout (read_timeout, 20 ms) until the device goes, so a
//     stop request is seen within it. read_link() feeds its decoder through the SampleStamper,
//     which numbers the samples (from 0 per run(), on across reconnects), times them and hands
//     them to the sink.
//   - a read error that is not a loss is counted; ten in a row count as a loss.
//   - when the device goes away it calls close_link() (the driver closes it and forgets partial
//     frames), counts an outage and reopens with the same backoff. After a connection that
//     lasted at least 1 s the backoff starts again from reconnect_min; a device that opens and
//     fails at once keeps backing off instead of spinning.
//   - logs each state change once through options.log: opened, lost, reopened (after how long
//     and how many attempts), a changed reason for not opening, never once per retry or read.
//     After a loss, "absent" reasons are not logged: the loss line said so.
//
// The link counters and the snapshots behind health() are atomics or taken under a small
// lock, readable from any thread while run() goes on.
#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <string_view>
#include <variant>

#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/driver_log.hpp"
#include "posefair/drivers/reconnect_backoff.hpp"
#include "posefair/drivers/time_base.hpp"

namespace posefair::drivers {

class SampleStamper;  // drivers/src/sample_stamper.hpp

// The options every device driver has (its own options struct derives from this).
struct DeviceLinkOptions : ReconnectSettings {
  std::uint32_t stream_id = 0;  // every sample's stream id
  TimeSource time_source = TimeSource::Auto;
  TimeBaseOptions time_base;
  double read_timeout = 0.02;   // s: poll timeout of one read, in (0, 0.05]
  DriverLog log;                // may be empty; called from run()'s thread. Messages do not
                                // repeat the driver's name: the receiver adds its context.
  std::string name;             // for logs; each driver has its default
};

class DeviceLinkDriver : public Driver {
 public:
  std::string_view name() const override { return name_; }
  // Runs until stop is requested (it never ends by itself: a lost device is waited for).
  // Returns within about read_timeout of the request. One run() at a time.
  void run(std::stop_token stop, SampleSink& sink) final;
  std::optional<DeviceHealth> health() const final;

  // Counters, readable from any thread while run() goes on.
  std::uint64_t samples() const { return samples_.load(std::memory_order_relaxed); }     // push() true
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }     // push() false
  std::uint64_t outages() const { return outages_.load(std::memory_order_relaxed); }     // device lost while open
  std::uint64_t reconnects() const { return reconnects_.load(std::memory_order_relaxed); }  // reopened after an outage
  std::uint64_t open_failures() const { return open_failures_.load(std::memory_order_relaxed); }  // failed open attempts
  std::uint64_t read_errors() const { return read_errors_.load(std::memory_order_relaxed); }  // transient read failures
  std::uint64_t time_base_fallbacks() const { return fallbacks_.load(std::memory_order_relaxed); }
  bool connected() const { return connected_.load(std::memory_order_acquire); }
  bool device_time_trusted() const { return trusted_.load(std::memory_order_relaxed); }
  DecoderCounters decoder_counters() const;     // snapshot after the last read
  TimeBaseCounters time_base_counters() const;  // snapshot after the last read
  std::string device_path() const;              // what was opened last ("" before the first open)

 protected:
  // Throws std::invalid_argument, the message starting with `kind` ("serial: ..."): bad
  // backoff, read timeout or time base options.
  DeviceLinkDriver(std::string_view kind, const DeviceLinkOptions& options);

  const DeviceLinkOptions& link_options() const { return link_; }
  void set_name(std::string name) { name_ = std::move(name); }
  void log(LogLevel level, const std::string& message) const;

  // An opened device, for the log: "opened <where><details>", "reopened <where> after ...".
  struct LinkOpened {
    std::string path;     // for device_path()
    std::string where;    // e.g. "usb 1a86:7523 -> /dev/ttyUSB0"
    std::string details;  // e.g. " at 115200 8N1, protocol witmotion, time source auto"
    std::string note;     // worth one warning when it changes ("" = none)
  };
  // Why an open failed. Each reason is logged once per wait.
  struct LinkOpenFailure {
    unsigned reason = 0;  // the driver's own reason, < 32
    bool absent = false;  // the device is not there (yet): a warning, and expected after a loss
    std::string kind;     // "" or a word for the log: "cannot open (<kind>): <message>"
    std::string message;
  };
  // What one read_link() did.
  struct LinkRead {
    enum class Error { None, Transient, Gone };
    bool decoded = false;  // bytes or frames went to the decoder
    Error error = Error::None;
    std::string message;   // with an error: why
  };

 private:
  // The driver's hooks, all called from run()'s thread.
  // Opens the device and readies the decoder for a new connection.
  virtual std::variant<LinkOpened, LinkOpenFailure> open_link() = 0;
  // Waits at most timeout_ms for data and feeds what came to the decoder through `stamper`.
  virtual LinkRead read_link(int timeout_ms, SampleStamper& stamper) = 0;
  // Closes the device (if open) and makes the decoder forget partial frames.
  virtual void close_link() = 0;
  // The decoder counters that decoder_counters() and health() show.
  virtual DecoderCounters link_decoder_counters() const = 0;
  // The link in "lost <it> (<why>)".
  virtual std::string lost_link_text() const { return "the device"; }

  void publish_snapshots(const TimeBase& time_base);

  DeviceLinkOptions link_;
  std::string name_;

  std::atomic<std::uint64_t> samples_{0}, dropped_{0}, outages_{0}, reconnects_{0}, open_failures_{0}, read_errors_{0},
      fallbacks_{0};
  std::atomic<bool> connected_{false}, trusted_{false};
  mutable std::mutex snapshot_mutex_;
  DecoderCounters decoder_snapshot_;
  TimeBaseCounters time_base_snapshot_;
  std::string device_path_;
};

}  // namespace posefair::drivers
