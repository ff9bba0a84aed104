#pragma once
// One CAN frame as a CAN decoder sees it: the identifier with the flags of Linux's canid_t
// (linux/can.h: EFF, RTR, ERR in the top three bits), a classic (0..8 bytes) or CAN FD
// (0..64 bytes) payload with the FD flags, and the time it was received. A plain value with no
// kernel header behind it, so the decoders stay pure and the tests and fuzz targets build
// anywhere; the SocketCAN driver copies struct can_frame / canfd_frame into it field by field
// (the bit values below are the kernel's, so the id and the flags copy unchanged).
#include <array>
#include <cstdint>
#include <span>

namespace posefair::formats {

struct CanFrame {
  // canid_t flags (linux/can.h)
  static constexpr std::uint32_t kEffFlag = 0x80000000u;  // 29-bit (extended) identifier
  static constexpr std::uint32_t kRtrFlag = 0x40000000u;  // remote transmission request
  static constexpr std::uint32_t kErrFlag = 0x20000000u;  // error frame (the id holds the error class)
  static constexpr std::uint32_t kSffMask = 0x000007FFu;
  static constexpr std::uint32_t kEffMask = 0x1FFFFFFFu;
  // canfd_frame.flags (linux/can.h)
  static constexpr std::uint8_t kFdBrs = 0x01;  // bit rate switch
  static constexpr std::uint8_t kFdEsi = 0x02;  // error state indicator of the sender
  static constexpr std::uint8_t kFdFdf = 0x04;  // marks a CAN FD frame (kernels >= 5.14 set it)
  static constexpr std::size_t kMaxClassic = 8;
  static constexpr std::size_t kMaxFd = 64;

  std::uint32_t can_id = 0;  // identifier | kEffFlag | kRtrFlag | kErrFlag, as canid_t
  std::uint8_t len = 0;      // payload bytes: 0..8 classic, 0..64 FD (for RTR: the requested length)
  bool fd = false;           // a CAN FD frame
  std::uint8_t fd_flags = 0; // kFdBrs | kFdEsi | kFdFdf, FD frames only
  std::array<std::uint8_t, kMaxFd> data{};
  double timestamp = 0.0;    // s: receive time (SO_TIMESTAMPNS, or the time in a candump log)

  bool extended() const { return (can_id & kEffFlag) != 0; }
  bool remote() const { return (can_id & kRtrFlag) != 0; }
  bool error() const { return (can_id & kErrFlag) != 0; }
  // The 11- or 29-bit identifier without the flags.
  std::uint32_t id() const { return can_id & (extended() ? kEffMask : kSffMask); }
  std::span<const std::uint8_t> payload() const { return {data.data(), remote() ? 0u : len}; }

  // A data frame with the given identifier (29-bit when `extended`) and payload (at most 8
  // bytes for a classic frame, 64 for FD; more is cut off).
  static CanFrame make(std::uint32_t id, bool extended, std::span<const std::uint8_t> bytes, double timestamp = 0.0,
                       bool fd = false) {
    CanFrame f;
    f.can_id = extended ? (id & kEffMask) | kEffFlag : id & kSffMask;
    const std::size_t max = fd ? kMaxFd : kMaxClassic;
    f.len = static_cast<std::uint8_t>(bytes.size() < max ? bytes.size() : max);
    for (std::size_t i = 0; i < f.len; ++i) f.data[i] = bytes[i];
    f.fd = fd;
    f.timestamp = timestamp;
    return f;
  }
};

// The payload lengths a CAN FD frame can have (DLC 0..15): 0..8, 12, 16, 20, 24, 32, 48, 64.
inline bool valid_fd_length(std::size_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

}  // namespace posefair::formats
