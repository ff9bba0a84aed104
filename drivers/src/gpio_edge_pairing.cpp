// The edge pairing rule (gpio_edge_pairing.hpp states it; docs/hid-gpio.md explains it).
// Why the latest edge in the window and not the earliest: with a window narrower than the
// sample period there is at most one right edge; when a glitch adds a second one, the later of
// the two is the one closer to the bytes that follow, and the earlier one stays counted.
#include "posefair/drivers/gpio_edge_pairing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace posefair::drivers {

namespace {
constexpr double kNever = -std::numeric_limits<double>::infinity();
}

EdgePairer::EdgePairer(const EdgePairingOptions& options)
    : options_(options), last_paired_(kNever), latest_receive_(kNever) {
  if (!std::isfinite(options.tolerance_min) || !std::isfinite(options.tolerance_max) || options.tolerance_min < 0.0 ||
      options.tolerance_max < options.tolerance_min)
    throw std::invalid_argument("GPIO edge pairing: need 0 <= tolerance_min <= tolerance_max (seconds, finite)");
}

void EdgePairer::drop_front(std::size_t n) {
  std::copy(edges_.begin() + static_cast<std::ptrdiff_t>(n), edges_.begin() + static_cast<std::ptrdiff_t>(count_), edges_.begin());
  count_ -= n;
}

void EdgePairer::add_edge(double time) {
  ++counters_.edges;
  if (!std::isfinite(time) || time <= last_paired_) {
    ++counters_.late_edges;
    return;
  }
  if (count_ == kMaxPending) {
    ++counters_.overflow;
    drop_front(1);
  }
  // Sorted insert; edges nearly always arrive in order, so this is an append.
  std::size_t at = count_;
  while (at > 0 && edges_[at - 1] > time) {
    edges_[at] = edges_[at - 1];
    --at;
  }
  edges_[at] = time;
  ++count_;
}

PairedTime EdgePairer::pair(double receive_time) {
  ++counters_.samples;
  latest_receive_ = std::max(latest_receive_, receive_time);
  // 1. Expire edges no sample can claim any more.
  const double expire_before = latest_receive_ - options_.tolerance_max;
  std::size_t expired = 0;
  while (expired < count_ && edges_[expired] < expire_before) ++expired;
  counters_.extra_edges += expired;
  drop_front(expired);
  // 2. The latest edge inside [r − max, r − min].
  const double lo = receive_time - options_.tolerance_max, hi = receive_time - options_.tolerance_min;
  std::size_t first_in = 0;
  while (first_in < count_ && edges_[first_in] < lo) ++first_in;
  std::size_t end_in = first_in;
  while (end_in < count_ && edges_[end_in] <= hi) ++end_in;
  if (end_in == first_in) {  // 3. missing
    ++counters_.missing;
    return {receive_time, false};
  }
  const double edge = edges_[end_in - 1];
  // Edges before the paired one (inside the window, or before it for an out-of-order sample)
  // can no longer be paired without going back in time: dropped as extra.
  counters_.extra_edges += end_in - 1;
  drop_front(end_in);
  last_paired_ = edge;
  ++counters_.paired;
  return {edge, true};
}

void EdgePairer::reset() {
  count_ = 0;
  last_paired_ = kNever;
  latest_receive_ = kNever;
}

}  // namespace posefair::drivers
