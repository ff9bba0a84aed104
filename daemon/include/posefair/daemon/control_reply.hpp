#pragma once
// The JSON objects posefaird answers on the control socket (docs/operations.md, "Control
// socket"): pure functions of the stats and tables they report. Each reply is one object with
// "ok"; a failure has "error" (a sentence) and "exit" (the exit status `posefair ctl` uses,
// core/error.hpp).
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/error.hpp"
#include "posefair/daemon/stage_latency.hpp"
#include "posefair/daemon/stream_counters.hpp"
#include "posefair/daemon/subscriber_table.hpp"
#include "posefair/daemon/subscription_handler.hpp"

namespace posefair::daemon {

// A JSON string literal (quotes and escapes) and a number (17 significant digits; non-finite as null).
std::string json_string(std::string_view s);
std::string json_number(double v);

std::string control_error_reply(const std::string& message, ErrorKind kind);

// "streams": [...] (no braces): per stream its counters, the emitted rate over `seconds` since
// `previous` (null without one), latency percentiles (µs, since start) and the adaptation state.
std::string streams_member(const std::vector<StreamStats>& now, const std::vector<StreamStats>& previous, double seconds);
// "stages": {...}: the pipeline's latency by stage since start (stage_latency.hpp), each with its
// count and p50/p99/p99.9/max in µs (null when that hop does not exist or saw nothing).
std::string stages_member(const StageLatencySnapshot& stages);
// "subscribers": [...]: address, encoding, streams, lease left and poses sent; now_ns on the steady clock.
std::string subscribers_member(const std::vector<SubscriberTable::Listed>& list, std::int64_t now_ns);
// "subscription": {...}: the port's counters and the amplification factor before verification.
std::string subscription_member(const SubscriptionHandler& handler, std::size_t subscribers);

}  // namespace posefair::daemon
