#pragma once
// How a driver logs: drivers/ has no logger of its own, so each driver is given a DriverLog
// and the daemon routes the lines to its logger under the stream's name.
#include <functional>
#include <string_view>

namespace posefair::drivers {

// Severity of a driver's log line.
enum class LogLevel { Debug, Info, Warn, Error };
using DriverLog = std::function<void(LogLevel, std::string_view)>;

}  // namespace posefair::drivers
