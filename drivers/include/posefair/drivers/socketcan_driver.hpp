#pragma once
// The SocketCAN driver (docs/can-devices.md): trackers on a CAN bus read through a raw CAN
// socket (PF_CAN, CAN_RAW) bound to one named interface (can0, vcan0), each frame decoded by a
// CAN protocol decoder (can_decoder.hpp), each sample timed (time_base.hpp) and handed to the sink.
//
// The link (opening with backoff, losses, reconnects, counters, health, the log lines) is
// DeviceLinkDriver's (device_link_driver.hpp). Here:
//   - opens the socket: kernel receive filters from decoder.filters() (CAN_RAW_FILTER), every
//     error class asked for (CAN_RAW_ERR_FILTER), CAN FD frames when `fd` (CAN_RAW_FD_FRAMES),
//     kernel receive timestamps (SO_TIMESTAMPNS). An interface that does not exist yet or is
//     down is "absent": a failed open retried with the backoff.
//   - waits with poll() and a short timeout (read_timeout, 20 ms); then reads every queued
//     frame (recvmsg) before waiting again.
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
//   - the interface is gone when it goes down (ENETDOWN) or away (ENODEV): the socket is
//     closed and the decoder reset; it starts afresh on the new socket.
//
// Raw CAN sockets need no device node and no capability (see docs/can-devices.md).
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/drivers/can_decoder.hpp"
#include "posefair/drivers/device_link_driver.hpp"

namespace posefair::drivers {

// stream_id, reconnect_min/max, time_source, time_base, read_timeout, log and name are the
// link's (DeviceLinkOptions); the default name is "socketcan:<interface> (<protocol>)".
struct SocketCanDriverOptions : DeviceLinkOptions {
  std::string interface;               // e.g. "can0"; at most 15 characters (IFNAMSIZ − 1)
  std::string protocol;                // CAN decoder registry name, used when `decoder` is null
  OptionMap decoder_options;           // its options (can_decoder.hpp, core/options.hpp)
  std::unique_ptr<CanDecoder> decoder; // an injected decoder (tests); takes the place of `protocol`
  bool fd = false;                     // also receive CAN FD frames (CAN_RAW_FD_FRAMES)
};

// Error frame classes (the bits of an error frame's can_id, linux/can/error.h), in bit order.
inline constexpr std::size_t kCanErrorClasses = 10;
// "tx-timeout", "lost-arbitration", "controller", "protocol", "transceiver", "no-ack",
// "bus-off", "bus-error", "restarted", "error-counter".
std::string_view can_error_class_name(std::size_t bit);

class SocketCanDriver final : public DeviceLinkDriver {
 public:
  // Throws std::invalid_argument: no or too long an interface name, an unknown protocol (the
  // message lists the known ones), an option the decoder refuses, bad backoff or time base.
  explicit SocketCanDriver(SocketCanDriverOptions options);
  ~SocketCanDriver() override;

  std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }      // frames read (any kind)
  std::uint64_t fd_frames() const { return fd_frames_.load(std::memory_order_relaxed); }  // of them CAN FD
  std::uint64_t error_frames() const { return error_frames_.load(std::memory_order_relaxed); }
  // Error frames with class bit `bit` (0 .. kCanErrorClasses − 1) set; a frame can carry several.
  std::uint64_t error_class_count(std::size_t bit) const {
    return bit < kCanErrorClasses ? error_classes_[bit].load(std::memory_order_relaxed) : 0;
  }
  std::uint64_t bus_off() const { return bus_off_.load(std::memory_order_relaxed); }  // bus-off events
  CanFrameCounters frame_counters() const;  // the decoder's, snapshot after the last batch of reads
  std::string_view protocol() const { return decoder_->protocol(); }

 private:
  std::variant<LinkOpened, LinkOpenFailure> open_link() override;
  LinkRead read_link(int timeout_ms, SampleStamper& stamper) override;
  void close_link() override;
  DecoderCounters link_decoder_counters() const override { return decoder_->counters(); }
  std::string lost_link_text() const override { return "interface " + options_.interface; }
  void count_error_frame(const CanFrame& frame);

  SocketCanDriverOptions options_;
  std::unique_ptr<CanDecoder> decoder_;
  std::vector<CanFilter> filters_;
  struct Bus;                  // the socket and the read batch (socketcan_driver.cpp)
  std::unique_ptr<Bus> bus_;   // run()'s thread only

  std::atomic<std::uint64_t> frames_{0}, fd_frames_{0}, error_frames_{0}, bus_off_{0};
  std::array<std::atomic<std::uint64_t>, kCanErrorClasses> error_classes_{};
  // Error logging state (run()'s thread only): the controller state last logged, and the
  // classes already logged since the last open.
  int controller_state_ = 0;
  std::uint32_t logged_classes_ = 0;
  mutable std::mutex frame_mutex_;
  CanFrameCounters frame_snapshot_;
};

}  // namespace posefair::drivers
