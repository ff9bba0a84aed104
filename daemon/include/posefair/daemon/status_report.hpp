#pragma once
// Text for operators: the per-stream counter lines posefaird logs periodically, on SIGUSR1 and
// at exit, and the one-line summary it sends to systemd as STATUS=. Pure functions of two
// stats snapshots (rates and interval percentiles come from their difference).
#include <string>
#include <vector>

#include "posefair/daemon/stream_counters.hpp"

namespace posefair::daemon {

// "stream head (id 1, replay:/x.csv): received 2000 (285.7/s), dropped 0 (ring 0, publish 0),
//  rejected 0, out-of-order 0, emitted 2000, clamped 12, restarts 1, published 2000,
//  send failures 0, recorded 2000 (dropped 0), latency µs p50 41 p90 60 p99 95 max 180"
// followed, for a stream with a device (serial), by its link: "; device connected, outages 1,
//  reconnects 1, open failures 3, read errors 0, frames 2000, bad 2, resyncs 3 (skipped 41
//  bytes), device time (fallbacks 0)".
// `previous` may be empty (then rates are left out); `seconds` is the time between the two.
std::vector<std::string> counter_lines(const std::vector<StreamStats>& now, const std::vector<StreamStats>& previous,
                                       double seconds);

// "head 285.7/s drop 0 p99 95us; hand 1000.0/s drop 3 p99 120us outages 1 bad 2" (rates of
// emitted poses; a device stream adds outages and bad frames, and DISCONNECTED while away).
std::string status_line(const std::vector<StreamStats>& now, const std::vector<StreamStats>& previous, double seconds);

}  // namespace posefair::daemon
