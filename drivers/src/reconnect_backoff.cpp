// The reconnect policy; see reconnect_backoff.hpp.
#include "posefair/drivers/reconnect_backoff.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "link_log_text.hpp"

namespace posefair::drivers {

void validate(const ReconnectSettings& s, std::string_view who) {
  if (!(s.reconnect_min > 0.0) || !std::isfinite(s.reconnect_min))
    throw std::invalid_argument(std::string(who) + ": reconnect_min must be finite and > 0");
  if (!(s.reconnect_max >= s.reconnect_min) || !std::isfinite(s.reconnect_max))
    throw std::invalid_argument(std::string(who) + ": reconnect_max must be finite and >= reconnect_min");
}

double ReconnectBackoff::next() {
  const double wait = delay_;
  delay_ = std::min(delay_ * 2.0, settings_.reconnect_max);
  return wait;
}

std::string ReconnectBackoff::describe() const {
  return backoff_text(settings_.reconnect_min) + " .. " + backoff_text(settings_.reconnect_max);
}

}  // namespace posefair::drivers
