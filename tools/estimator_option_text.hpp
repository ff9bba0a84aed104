#pragma once
// Estimator options from the command line: KEY=VALUE texts read by the type the estimator
// declares for KEY (posefair fuse --set, posefair calibrate does not need it).
#include <string>
#include <vector>

#include "posefair/core/orientation_estimator.hpp"

namespace posefair::tools {

// Throws std::invalid_argument "KEY=VALUE: <why>" for a text without '=', an undeclared key
// (listing the declared ones) or a value that is not of the key's type.
OptionMap parse_estimator_settings(const OrientationEstimatorEntry& entry, const std::vector<std::string>& settings);

}  // namespace posefair::tools
