#pragma once
// CLOCK_MONOTONIC in seconds: the clock of Sample::receive_time, of kernel GPIO edge events
// and of every driver's waits. Private to drivers/src.
#include <time.h>

namespace posefair::drivers {

inline double seconds_of(const timespec& ts) {
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double monotonic_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return seconds_of(ts);
}

}  // namespace posefair::drivers
