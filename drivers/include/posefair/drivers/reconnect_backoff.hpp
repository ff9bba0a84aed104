#pragma once
// The one reconnect policy of every driver whose device or line can be absent (serial,
// SocketCAN, hidraw, the GPIO lines): after a failed attempt to open the device (or request the
// line) it waits reconnect_min, and each further failure doubles the wait up to reconnect_max.
// The configuration keys of a source have the same names (docs/config.md).
#include <string>
#include <string_view>

namespace posefair::drivers {

struct ReconnectSettings {
  double reconnect_min = 0.1;  // s: the first wait after a failed open; finite, > 0
  double reconnect_max = 5.0;  // s: waits double up to this; finite, >= reconnect_min
};

// Throws std::invalid_argument naming `who` ("serial: reconnect_min must be finite and > 0").
void validate(const ReconnectSettings& settings, std::string_view who);

// The wait before the next attempt, for one device or line.
class ReconnectBackoff {
 public:
  explicit ReconnectBackoff(const ReconnectSettings& settings) : settings_(settings), delay_(settings.reconnect_min) {}

  // The wait before the next attempt; the wait after that one is twice as long (at most
  // reconnect_max).
  double next();
  // After a success: the next failure waits reconnect_min again.
  void reset() { delay_ = settings_.reconnect_min; }
  const ReconnectSettings& settings() const { return settings_; }
  // "0.1 s .. 5 s", as the log lines say it.
  std::string describe() const;

 private:
  ReconnectSettings settings_;
  double delay_;
};

}  // namespace posefair::drivers
