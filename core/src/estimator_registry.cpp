// The orientation estimators, by name (orientation_estimator.hpp). A new one: its header with
// the entry, its .cpp in core/fusion.cmake, and one line here.
#include <stdexcept>

#include "posefair/core/madgwick_estimator.hpp"
#include "posefair/core/mahony_estimator.hpp"
#include "posefair/core/registry_lookup.hpp"
#include "posefair/core/vqf_estimator.hpp"

namespace posefair {

namespace {
constexpr const OrientationEstimatorEntry* kEstimators[] = {
    &kVqfEstimator,  // the default
    &kMadgwickEstimator,
    &kMahonyEstimator,
};
}  // namespace

std::span<const OrientationEstimatorEntry* const> orientation_estimator_entries() { return kEstimators; }

const OrientationEstimatorEntry* find_orientation_estimator(std::string_view name) {
  return find_entry(orientation_estimator_entries(), name);
}

std::vector<std::string> orientation_estimator_names() {
  return entry_names(orientation_estimator_entries());
}

std::unique_ptr<OrientationEstimator> make_orientation_estimator(std::string_view name,
                                                                 const OptionMap& options) {
  const OrientationEstimatorEntry* e = find_orientation_estimator(name);
  if (e == nullptr) {
    std::string known;
    for (const std::string& n : orientation_estimator_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown estimator '" + std::string(name) + "' (known: " + known + ")");
  }
  return e->make(options);
}

}  // namespace posefair
