#pragma once
// The tuning split of `posefair bench quality`: a tuned family's configuration is the one with
// the lowest mean error on a fold's training sequences (each relative to a reference row on
// the same sequence, so every sequence weighs the same), among those that fit the selection's
// lag budget on average over the training sequences (a lag estimate on one noisy sequence is
// good to about a millisecond); it is then scored on the fold's report sequences only.
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace posefair::tools {

// How a tuned row is chosen: the lowest aligned error (view b) within a lag budget, or the
// lowest delivered error (view a), which charges the delay in the error itself.
struct SelectionRule {
  const char* name;
  double budget_ms;  // view (b) budgets; ignored when delivered
  bool delivered;
};
inline constexpr SelectionRule kSelectionRules[] = {
    {"0 ms", 0.0, false}, {"10 ms", 10.0, false}, {"30 ms", 30.0, false}, {"delivered", 0.0, true}};

// A measured lag fits a budget up to this much (the resolution of the lag estimate), whatever
// the sample rate.
inline constexpr double kBudgetSlackMs = 1.0;

// candidates: indices of one family's configurations. relative_error(c, s): candidate c's
// error on sequence s over the reference's; lag_ms(c, s): its lag; the mean lag over `train`
// must not exceed max_lag_ms.
std::optional<std::size_t> pick_on_training(std::span<const std::size_t> candidates, std::span<const std::size_t> train,
                                            const std::function<double(std::size_t, std::size_t)>& relative_error,
                                            const std::function<double(std::size_t, std::size_t)>& lag_ms, double max_lag_ms);

struct Spread {
  double mean = 0.0, min = 0.0, max = 0.0;
  std::size_t count = 0;
  void add(double x);
  void finish();  // turns the running sum into the mean
};

// "mean (min–max)" with %.4g numbers, or the mean alone for one value.
std::string format_spread(const Spread& s);

}  // namespace posefair::tools
