#pragma once
// What a ring does when its consumer falls behind. Either way the loss is counted.
// A tiny header of its own so that the lock-free ring (spsc_ring.hpp) does not pull in the
// configuration loader; config.hpp includes this header for DaemonConfig's `overflow` key.

namespace posefair::daemon {

enum class OverflowPolicy {
  DropOldest,  // the producer always succeeds; the oldest unread item is overwritten
  DropNewest,  // the producer's push fails while the ring is full; the new item is lost
};

}  // namespace posefair::daemon
