#pragma once
// The upper median (the element at index n/2 once sorted) of a few values, reordered in place:
// what the engine's first-values estimates start from (the rate, the noise). No allocation.
#include <algorithm>
#include <span>

namespace posefair {

inline double upper_median(std::span<double> values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace posefair
