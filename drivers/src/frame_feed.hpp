#pragma once
// How the serial decoders keep a frame that a read split in two: the part of the stream a
// decoder could not decide yet stays for the next feed(), so the samples and counters never
// depend on where the reads split the bytes. Two shapes, by the protocol's framing.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

namespace posefair::drivers::detail {

// Fixed-size frames scanned in place (WitMotion, BNO08x RVC). scan(p, n, limit) decides the
// stream positions p[0], p[1], ... while they are < limit and returns where it stopped: >= limit,
// or < limit where a frame starts that needs bytes beyond p[n-1]. The bytes from there on (fewer
// than kFrameSize) are carried and decided with the next input; the input itself is scanned
// without copying.
template <std::size_t kFrameSize>
class SplitFrameCarry {
 public:
  template <typename Scan>
  void feed(std::span<const std::uint8_t> in, Scan&& scan) {
    std::size_t off = 0;
    if (carry_len_ > 0) {
      // Decide the positions that start in the carried bytes, with enough input appended to
      // complete any frame starting there.
      std::array<std::uint8_t, 2 * kFrameSize> joined{};
      const std::size_t head = std::min(in.size(), kFrameSize - 1);
      std::memcpy(joined.data(), carry_.data(), carry_len_);
      if (head > 0) std::memcpy(joined.data() + carry_len_, in.data(), head);
      const std::size_t n = carry_len_ + head;
      const std::size_t pos = scan(joined.data(), n, carry_len_);
      if (pos < carry_len_) {  // still short of a whole frame: all of `in` is in `joined`
        carry_len_ = n - pos;
        std::memmove(carry_.data(), joined.data() + pos, carry_len_);
        return;
      }
      off = pos - carry_len_;
      carry_len_ = 0;
    }
    const std::size_t rest = in.size() - off;
    const std::size_t pos = scan(in.data() + off, rest, rest);
    carry_len_ = rest - pos;
    if (carry_len_ > 0) std::memcpy(carry_.data(), in.data() + off + pos, carry_len_);
  }

  void reset() { carry_len_ = 0; }

 private:
  std::array<std::uint8_t, kFrameSize> carry_{};
  std::size_t carry_len_ = 0;
};

// Variable-length messages of at most kCapacity bytes (Xsens, posefair). The input is copied
// into a buffer; process(p, n) handles every whole message in p[0, n) and returns how many bytes
// it used. The rest, the start of an incomplete message, stays buffered.
template <std::size_t kCapacity>
class MessageBuffer {
 public:
  template <typename Process>
  void feed(std::span<const std::uint8_t> in, Process&& process) {
    while (!in.empty()) {
      const std::size_t n = std::min(in.size(), buf_.size() - held_);
      std::memcpy(buf_.data() + held_, in.data(), n);
      held_ += n;
      in = in.subspan(n);
      const std::size_t used = process(static_cast<const std::uint8_t*>(buf_.data()), held_);
      std::memmove(buf_.data(), buf_.data() + used, held_ - used);
      held_ -= used;
    }
  }

  void reset() { held_ = 0; }

 private:
  std::array<std::uint8_t, kCapacity> buf_{};
  std::size_t held_ = 0;
};

}  // namespace posefair::drivers::detail
