#pragma once
// The serial driver (docs/devices.md, "Serial"): a tracker or IMU on a serial port (USB-serial
// adapter, CDC-ACM, a UART), its byte stream decoded by a protocol decoder (decoder.hpp), each
// sample timed (time_base.hpp) and handed to the sink.
//
// run():
//   - opens the port (serial_port.hpp). While the device is absent or refuses, it retries with
//     exponential backoff (reconnect_min, doubling, up to reconnect_max).
//   - reads with poll() and a short timeout (read_timeout, 20 ms), so a stop request is seen
//     within it, also while waiting for data or for the device.
//   - feeds the decoder whatever each read returned; receive_time is CLOCK_MONOTONIC taken right
//     after that read, shared by every sample decoded from it. The TimeBase turns (receive
//     time, device time) into Sample::time; sequence numbers count from 0 per run() and keep
//     counting across reconnects.
//   - when the device goes away (unplugged: EIO, ENXIO, ENODEV, hangup) it closes the port,
//     resets the decoder, counts an outage and reopens with the same backoff; the decoder and
//     the time base start afresh on the new connection.
//   - logs each state change once through options.log: opened, lost, reopened (after how long
//     and how many attempts), a changed reason for not opening; never once per retry or read.
//
// Counters are atomics (or snapshots under a small lock) readable from any thread.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <stop_token>
#include <string>
#include <string_view>

#include "posefair/drivers/decoder.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/serial_port.hpp"
#include "posefair/drivers/time_base.hpp"

namespace posefair::drivers {

// Severity of a driver's log line; the daemon routes them to its logger (drivers/ has none).
enum class LogLevel { Debug, Info, Warn, Error };
using DriverLog = std::function<void(LogLevel, std::string_view)>;

struct SerialDriverOptions {
  SerialPortSpec port;
  SerialSettings settings;
  std::string protocol;                // decoder registry name (decoder.hpp), used when `decoder` is null
  OptionMap decoder_options;           // its options (decoder.hpp, device_options.hpp)
  std::unique_ptr<Decoder> decoder;    // an injected decoder (tests); takes the place of `protocol`
  std::uint32_t stream_id = 0;         // every sample's stream id
  double reconnect_min = 0.1;          // s: the first wait after a failed open; finite, > 0
  double reconnect_max = 5.0;          // s: waits double up to this; >= reconnect_min
  TimeSource time_source = TimeSource::Auto;
  TimeBaseOptions time_base;
  double read_timeout = 0.02;          // s: poll timeout of one read, in (0, 0.05]
  std::size_t read_buffer = 4096;      // bytes per read, > 0
  DriverLog log;                       // may be empty; called from run()'s thread. Messages do not
                                       // repeat the driver's name: the receiver adds its context.
  std::string name;                    // for logs; default "serial:<device or usb id>"
};

class SerialDriver final : public Driver {
 public:
  // Throws std::invalid_argument: no device and no USB id, an unknown protocol (the message
  // lists the known ones), an option the decoder refuses, bad settings or backoff.
  explicit SerialDriver(SerialDriverOptions options);

  std::string_view name() const override { return name_; }
  // Runs until stop is requested (it never ends by itself: a lost device is waited for).
  // Returns within about read_timeout of the request. One run() at a time.
  void run(std::stop_token stop, SampleSink& sink) override;

  // Counters, readable from any thread while run() goes on.
  std::uint64_t bytes() const { return bytes_.load(std::memory_order_relaxed); }        // bytes read
  std::uint64_t samples() const { return samples_.load(std::memory_order_relaxed); }    // push() true
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }    // push() false
  std::uint64_t outages() const { return outages_.load(std::memory_order_relaxed); }    // device lost while open
  std::uint64_t reconnects() const { return reconnects_.load(std::memory_order_relaxed); }  // reopened after an outage
  std::uint64_t open_failures() const { return open_failures_.load(std::memory_order_relaxed); }  // failed open attempts
  std::uint64_t read_errors() const { return read_errors_.load(std::memory_order_relaxed); }  // transient read failures
  std::uint64_t time_base_fallbacks() const { return fallbacks_.load(std::memory_order_relaxed); }
  bool connected() const { return connected_.load(std::memory_order_acquire); }
  bool device_time_trusted() const { return trusted_.load(std::memory_order_relaxed); }
  DecoderCounters decoder_counters() const;    // snapshot after the last read
  TimeBaseCounters time_base_counters() const; // snapshot after the last read
  std::string device_path() const;             // the node opened last ("" before the first open)
  std::string_view protocol() const { return decoder_->protocol(); }
  std::optional<DeviceHealth> health() const override;

 private:
  void log(LogLevel level, const std::string& message) const;
  void publish_snapshots(const TimeBase& time_base);

  SerialDriverOptions options_;
  std::unique_ptr<Decoder> decoder_;
  std::string name_;

  std::atomic<std::uint64_t> bytes_{0}, samples_{0}, dropped_{0}, outages_{0}, reconnects_{0}, open_failures_{0},
      read_errors_{0}, fallbacks_{0};
  std::atomic<bool> connected_{false}, trusted_{false};
  mutable std::mutex snapshot_mutex_;
  DecoderCounters decoder_snapshot_;
  TimeBaseCounters time_base_snapshot_;
  std::string device_path_;
};

}  // namespace posefair::drivers
