// WindowConfig validation and smoothing_for_cutoff.
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "posefair/core/banded_cholesky.hpp"
#include "posefair/core/fairing_window.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

struct Invalid {
  std::string field;  // the message must name it
  std::function<void(WindowConfig&)> edit;
};

TEST(WindowConfig, EachInvalidFieldIsRejectedByNameAtConstruction) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Invalid> cases = {
      {"order", [](WindowConfig& c) { c.order = 4; }},
      {"order", [](WindowConfig& c) { c.order = 1; }},
      {"window", [](WindowConfig& c) { c.window = 2; }},  // order 2 needs 3
      {"window", [](WindowConfig& c) { c.order = 3; c.window = 3; c.lag = 0; }},
      {"window", [](WindowConfig& c) { c.window = 5000; }},
      {"lag", [](WindowConfig& c) { c.window = 8; c.lag = 8; }},
      {"lag", [](WindowConfig& c) { c.lag = -1; }},
      {"iterations", [](WindowConfig& c) { c.iterations = -1; }},
      {"smoothing_r", [](WindowConfig& c) { c.smoothing_r = -1.0; }},
      {"smoothing_r", [=](WindowConfig& c) { c.smoothing_r = nan; }},
      {"smoothing_r", [=](WindowConfig& c) { c.smoothing_r = inf; }},
      {"smoothing_r", [](WindowConfig& c) { c.smoothing_r = 2.0 * kMaxSmoothing; }},
      {"smoothing_t", [](WindowConfig& c) { c.smoothing_t = -0.5; }},
      {"continuity", [](WindowConfig& c) { c.continuity = -1.0; }},
      {"continuity", [=](WindowConfig& c) { c.continuity = inf; }},
      {"continuity", [](WindowConfig& c) { c.continuity = 0.5; c.window = 600; }},
      {"lambda_r", [](WindowConfig& c) { c.lambda_r = 0.0; }},
      {"lambda_r", [](WindowConfig& c) { c.lambda_r = 1.5; }},
      {"lambda_t", [](WindowConfig& c) { c.lambda_t = 0.0; }},
      {"epsilon_r", [](WindowConfig& c) { c.epsilon_r = 0.0; }},
      {"epsilon_r", [](WindowConfig& c) { c.epsilon_r = -0.1; }},
      {"epsilon_r", [=](WindowConfig& c) { c.epsilon_r = nan; }},
      {"epsilon_t", [](WindowConfig& c) { c.epsilon_t = 0.0; }},
      {"epsilon_t", [](WindowConfig& c) { c.epsilon_t = -3.0; }},
      {"bound", [](WindowConfig& c) { c.solver = WindowSolver::Linear; c.bound = BoundPolicy::Window; }},
  };
  for (const Invalid& bad : cases) {
    WindowConfig c;
    bad.edit(c);
    SCOPED_TRACE(bad.field);
    EXPECT_THAT([&] { FairingWindow w(c); }, ThrowsMessage<std::invalid_argument>(HasSubstr(bad.field)));
    EXPECT_THAT([&] { validate(c); }, ThrowsMessage<std::invalid_argument>(HasSubstr(bad.field)));
  }
}

TEST(WindowConfig, BoundaryValuesAreValid) {
  std::vector<WindowConfig> ok(7);
  ok[1].order = 3;
  ok[1].window = 4;
  ok[1].lag = 3;  // the largest lag
  ok[2].window = 3;  // the smallest window for order 2
  ok[3].smoothing_r = 0.0;
  ok[3].smoothing_t = 0.0;
  ok[4].lambda_r = 1.0;
  ok[4].lambda_t = 1.0;
  ok[5].solver = WindowSolver::GaussNewton;
  ok[5].window = 32;  // the iterative solvers take W in samples and a fixed μ
  ok[5].smoothing_r = 100.0;
  ok[5].bound = BoundPolicy::Window;
  ok[6].solver = WindowSolver::DampedSweeps;
  ok[6].window = 32;
  ok[6].bound = BoundPolicy::Window;
  ok[6].epsilon_r = 1e-9;
  ok[6].epsilon_t = 1e-9;
  for (std::size_t i = 0; i < ok.size(); ++i) {
    EXPECT_NO_THROW(validate(ok[i])) << i;
    EXPECT_NO_THROW(FairingWindow{ok[i]}) << i;
  }
}

TEST(WindowConfig, AContinuityThatMakesTheOutputRecursionUnstableIsRefused) {
  // docs/engine.md: κ = 10, μ = 100, W = 32, L = 0, m = 3 has spectral radius 1.027.
  WindowConfig c;
  c.order = 3;
  c.window = 32;
  c.lag = 0;
  c.smoothing_r = c.smoothing_t = 100.0;
  c.continuity = 10.0;
  for (WindowSolver solver : {WindowSolver::Linear, WindowSolver::GaussNewton}) {
    c.solver = solver;
    EXPECT_THAT([&] { FairingWindow w(c); }, ThrowsMessage<std::invalid_argument>(HasSubstr("continuity"))) << static_cast<int>(solver);
  }
  c.solver = WindowSolver::Linear;
  c.continuity = 1.0;  // a moderate pull is stable
  EXPECT_NO_THROW(FairingWindow{c});
}

TEST(WindowConfig, InvalidGateSettingsAreRejected) {
  WindowConfig c;
  c.gate.gap_threshold = 0.0;
  EXPECT_THROW(FairingWindow{c}, std::invalid_argument);
  c = {};
  c.gate.unit_tolerance = 1.0;
  EXPECT_THROW(FairingWindow{c}, std::invalid_argument);
}

TEST(SmoothingForCutoff, IsTheDocumentedFormula) {
  for (int m : {2, 3}) {
    for (double fc : {0.5, 4.0, 20.0, 49.0}) {
      const double expected = std::pow(2.0 * std::sin(std::numbers::pi * fc / 100.0), -2.0 * m);
      EXPECT_NEAR(smoothing_for_cutoff(fc, 100.0, m), expected, 1e-12 * expected) << "m=" << m << " fc=" << fc;
    }
  }
  // Hand-computed: 2 sin(π/4) = √2, so μ = 2^(-m).
  EXPECT_NEAR(smoothing_for_cutoff(25.0, 100.0, 2), 0.25, 1e-14);
  EXPECT_NEAR(smoothing_for_cutoff(25.0, 100.0, 3), 0.125, 1e-14);
  // A lower cutoff smooths more.
  EXPECT_GT(smoothing_for_cutoff(2.0, 100.0, 2), smoothing_for_cutoff(4.0, 100.0, 2));
}

TEST(SmoothingForCutoff, RejectsCutoffsOutsideTheOpenIntervalBelowNyquist) {
  EXPECT_THROW(smoothing_for_cutoff(50.0, 100.0, 2), std::invalid_argument);
  EXPECT_THROW(smoothing_for_cutoff(60.0, 100.0, 2), std::invalid_argument);
  EXPECT_THROW(smoothing_for_cutoff(0.0, 100.0, 2), std::invalid_argument);
  EXPECT_THROW(smoothing_for_cutoff(-1.0, 100.0, 2), std::invalid_argument);
  EXPECT_THROW(smoothing_for_cutoff(4.0, 0.0, 2), std::invalid_argument);
  EXPECT_THROW(smoothing_for_cutoff(std::numeric_limits<double>::quiet_NaN(), 100.0, 2), std::invalid_argument);
  EXPECT_NO_THROW(smoothing_for_cutoff(49.9, 100.0, 2));
}

TEST(SmoothingForCutoff, TheSteadyStateSmootherPassesHalfTheAmplitudeAtTheCutoff) {
  // Far from the ends, (I + μ (D^m)ᵀD^m) x = sin(ω i) is solved by H(ω) sin(ω i) with
  // H = 1 / (1 + μ (2 sin(ω/2))^(2m)); μ from smoothing_for_cutoff makes H(ω_c) = 1/2
  // (an amplitude gain of one half, i.e. a quarter of the power).
  constexpr int n = 1200;
  for (int m : {2, 3}) {
    const double fc = 4.0, fs = 100.0;
    const double mu = smoothing_for_cutoff(fc, fs, m);
    std::vector<double> ones(n, 1.0);
    const BandedCholesky a = make_smoothing_system(n, m, mu, ones);
    const double omega = 2.0 * std::numbers::pi * fc / fs;
    std::vector<Vec3> x(n);
    for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = Vec3(std::sin(omega * i), std::cos(omega * i), 0.0);
    a.solve(x);
    double gain = 0.0;
    for (int i = n / 2 - 50; i < n / 2 + 50; ++i) gain = std::max(gain, std::hypot(x[static_cast<std::size_t>(i)].x(), x[static_cast<std::size_t>(i)].y()));
    EXPECT_NEAR(gain, 0.5, 1e-6) << "m=" << m;
  }
}

}  // namespace
}  // namespace posefair

namespace posefair {
namespace {

TEST(WindowConfig, GaussNewtonNeedsAtLeastOneIteration) {
  WindowConfig c;
  c.solver = WindowSolver::GaussNewton;
  c.iterations = 0;
  EXPECT_THROW(validate(c), std::invalid_argument);
  c.solver = WindowSolver::Linear;  // the linear solver ignores iterations
  EXPECT_NO_THROW(validate(c));
}

}  // namespace
}  // namespace posefair
