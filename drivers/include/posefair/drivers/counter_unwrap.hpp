#pragma once
// Forward-only unwrapping of a counter that wraps at 2^bits (a packet counter, a device clock):
// each step is taken modulo the counter's range, so the unwrapped value never decreases; a
// device restart looks like a rollover. Shared by the Xsens and CAN decoders.
#include <cstdint>

namespace posefair::drivers {

class CounterUnwrapper {
 public:
  explicit CounterUnwrapper(unsigned bits) : mask_(bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1) {}
  std::uint64_t update(std::uint64_t raw) {
    total_ = have_ ? total_ + ((raw - last_) & mask_) : raw & mask_;
    have_ = true;
    last_ = raw;
    return total_;
  }
  void reset() { have_ = false; }

 private:
  std::uint64_t mask_;
  std::uint64_t last_ = 0;
  std::uint64_t total_ = 0;
  bool have_ = false;
};

}  // namespace posefair::drivers
