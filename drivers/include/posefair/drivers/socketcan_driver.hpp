#pragma once
// The SocketCAN driver (docs/can-devices.md): trackers on a CAN bus read through a raw CAN
// socket (PF_CAN, CAN_RAW) bound to one named interface (can0, vcan0), each frame decoded by a
// CAN protocol decoder (can_decoder.hpp), each sample timed (time_base.hpp) and handed to the sink.
//
// run():
//   - opens the socket: kernel receive filters from decoder.filters() (CAN_RAW_FILTER), every
//     error class asked for (CAN_RAW_ERR_FILTER), CAN FD frames when `fd` (CAN_RAW_FD_FRAMES),
//     kernel receive timestamps (SO_TIMESTAMPNS). An interface that does not exist yet or is
//     down counts as a failed open and is retried with exponential backoff (reconnect_min,
//     doubling, up to reconnect_max).
//   - waits with poll() and a short timeout (read_timeout, 20 ms), so a stop request is seen
//     within it; then reads every queued frame (recvmsg) before waiting again.
//   - receive time: the kernel's timestamp of the frame. SO_TIMESTAMPNS (and SO_TIMESTAMPING's
//     software stamp alike) is CLOCK_REALTIME, while Sample::receive_time is CLOCK_MONOTONIC:
//     the driver measures realtime − monotonic around each batch of reads (monotonic, realtime,
//     monotonic; the offset taken at the midpoint) and subtracts it; the result is clamped to
//     the monotonic time after the read (a realtime step between the frame's arrival and the
//     read would otherwise put it in the future). Frames without a timestamp get the monotonic
//     time after the read.
//   - error frames are counted per error class (linux/can/error.h) and bus-off separately; the
//     log gets a line when the controller's state changes (active, warning, passive, bus-off,
//     restarted) and the first time each other class is seen after an open, never per frame.
//     Error frames are also fed to the decoder (it counts them in its frame counters).
//   - when the interface goes down (ENETDOWN) or away (ENODEV) the socket is closed, the
//     decoder reset, an outage counted, and it is reopened with the same backoff; the decoder
//     and the time base start afresh on the new socket.
//   - logs each state change once through options.log, like the serial driver.
//
// Raw CAN sockets need no device node and no capability (see docs/can-devices.md).
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <string_view>

#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/driver.hpp"
#include "posefair/drivers/serial_driver.hpp"  // LogLevel, DriverLog
#include "posefair/drivers/time_base.hpp"

namespace posefair::drivers {

struct SocketCanDriverOptions {
  std::string interface;               // e.g. "can0"; at most 15 characters (IFNAMSIZ − 1)
  std::string protocol;                // CAN decoder registry name, used when `decoder` is null
  OptionMap decoder_options;           // its options (can_decoder.hpp, device_options.hpp)
  std::unique_ptr<CanDecoder> decoder; // an injected decoder (tests); takes the place of `protocol`
  bool fd = false;                     // also receive CAN FD frames (CAN_RAW_FD_FRAMES)
  std::uint32_t stream_id = 0;
  double reconnect_min = 0.1;          // s: the first wait after a failed open; finite, > 0
  double reconnect_max = 5.0;          // s: waits double up to this; >= reconnect_min
  TimeSource time_source = TimeSource::Auto;
  TimeBaseOptions time_base;
  double read_timeout = 0.02;          // s: poll timeout, in (0, 0.05]
  DriverLog log;                       // may be empty; called from run()'s thread
  std::string name;                    // for logs; default "socketcan:<interface> (<protocol>)"
};

// Error frame classes (the bits of an error frame's can_id, linux/can/error.h), in bit order.
inline constexpr std::size_t kCanErrorClasses = 10;
// "tx-timeout", "lost-arbitration", "controller", "protocol", "transceiver", "no-ack",
// "bus-off", "bus-error", "restarted", "error-counter".
std::string_view can_error_class_name(std::size_t bit);

class SocketCanDriver final : public Driver {
 public:
  // Throws std::invalid_argument: no or too long an interface name, an unknown protocol (the
  // message lists the known ones), an option the decoder refuses, bad backoff or time base.
  explicit SocketCanDriver(SocketCanDriverOptions options);

  std::string_view name() const override { return name_; }
  // Runs until stop is requested (a missing or downed interface is waited for). Returns within
  // about read_timeout of the request. One run() at a time.
  void run(std::stop_token stop, SampleSink& sink) override;

  std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }      // frames read (any kind)
  std::uint64_t fd_frames() const { return fd_frames_.load(std::memory_order_relaxed); }  // of them CAN FD
  std::uint64_t error_frames() const { return error_frames_.load(std::memory_order_relaxed); }
  // Error frames with class bit `bit` (0 .. kCanErrorClasses − 1) set; a frame can carry several.
  std::uint64_t error_class_count(std::size_t bit) const {
    return bit < kCanErrorClasses ? error_classes_[bit].load(std::memory_order_relaxed) : 0;
  }
  std::uint64_t bus_off() const { return bus_off_.load(std::memory_order_relaxed); }  // bus-off events
  std::uint64_t samples() const { return samples_.load(std::memory_order_relaxed); }
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  std::uint64_t outages() const { return outages_.load(std::memory_order_relaxed); }
  std::uint64_t reconnects() const { return reconnects_.load(std::memory_order_relaxed); }
  std::uint64_t open_failures() const { return open_failures_.load(std::memory_order_relaxed); }
  std::uint64_t read_errors() const { return read_errors_.load(std::memory_order_relaxed); }
  bool connected() const { return connected_.load(std::memory_order_acquire); }
  DecoderCounters decoder_counters() const;       // snapshot after the last batch of reads
  CanFrameCounters frame_counters() const;        // the decoder's, snapshot as above
  TimeBaseCounters time_base_counters() const;
  std::string_view protocol() const { return decoder_->protocol(); }
  std::optional<DeviceHealth> health() const override;

 private:
  void log(LogLevel level, const std::string& message) const;
  void publish_snapshots(const TimeBase& time_base);
  void count_error_frame(const CanFrame& frame);

  SocketCanDriverOptions options_;
  std::unique_ptr<CanDecoder> decoder_;
  std::string name_;

  std::atomic<std::uint64_t> frames_{0}, fd_frames_{0}, error_frames_{0}, bus_off_{0}, samples_{0}, dropped_{0},
      outages_{0}, reconnects_{0}, open_failures_{0}, read_errors_{0}, fallbacks_{0};
  std::array<std::atomic<std::uint64_t>, kCanErrorClasses> error_classes_{};
  std::atomic<bool> connected_{false}, trusted_{false};
  // Error logging state (run()'s thread only): the controller state last logged, and the
  // classes already logged since the last open.
  int controller_state_ = 0;
  std::uint32_t logged_classes_ = 0;
  mutable std::mutex snapshot_mutex_;
  DecoderCounters decoder_snapshot_;
  CanFrameCounters frame_snapshot_;
  TimeBaseCounters time_base_snapshot_;
};

}  // namespace posefair::drivers
