#pragma once
// Which engine setting (a WindowConfig or GateConfig field) a check refused, as data: the
// daemon's config loader maps it to the TOML key that set it without reading the message.
#include <stdexcept>
#include <string>

namespace posefair {

enum class EngineSetting {
  Window,
  Lag,
  Horizon,
  Rate,
  Cutoff,
  Adaptation,
  Order,
  Solver,
  Iterations,
  SmoothingR,
  SmoothingT,
  Continuity,
  LambdaR,
  LambdaT,
  Variant,
  EpsilonR,
  EpsilonT,
  Bound,
  GapThreshold,
  UnitTolerance,
  OutlierThreshold,
};

// What validate(WindowConfig), FairingWindow and SampleGate throw for a refused setting. A
// std::invalid_argument, so callers that only want the message keep catching that.
class InvalidEngineSetting : public std::invalid_argument {
 public:
  InvalidEngineSetting(EngineSetting setting, const std::string& what) : std::invalid_argument(what), setting_(setting) {}
  EngineSetting setting() const noexcept { return setting_; }

 private:
  EngineSetting setting_;
};

}  // namespace posefair
