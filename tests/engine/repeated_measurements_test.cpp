// A stream read faster than its source updates (repeated_measurements.hpp): how it is told from
// a quantised sensor's chance repeats, and what the engine makes of it.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/repeated_measurements.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair {
namespace {

Sample at(double time, const Quat& q) {
  Sample s;
  s.time = time;
  s.orientation = q;
  return s;
}

// A slow sway (0.3–0.7 Hz, up to 0.4 rad), known at any time.
Quat sway(double t) {
  const double tau = 2.0 * std::numbers::pi;
  return so3::exp(Vec3(0.2 * std::sin(tau * 0.5 * t), 0.15 * std::sin(tau * 0.3 * t + 1.0), 0.1 * std::sin(tau * 0.7 * t + 2.0)));
}

// The sway measured at source_hz under noise (‖δ‖ < noise, dist on S³) and read at rate_hz:
// each sample the newest measurement taken at or before its time. truth: the sway at each
// sample's time.
std::vector<Sample> read_faster(double source_hz, double rate_hz, double seconds, double noise, std::uint64_t seed,
                                std::vector<Quat>& truth) {
  std::mt19937_64 rng(seed);
  std::vector<Sample> out;
  truth.clear();
  long measured = -1;
  Quat z = Quat::Identity();
  for (long i = 0; i < std::lround(seconds * rate_hz); ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    const long k = static_cast<long>(std::floor(t * source_hz + 1e-9));
    if (k != measured) {
      measured = k;
      z = (sway(static_cast<double>(k) / source_hz) * so3::exp(random_offset(rng, noise))).normalized();
    }
    out.push_back(at(t, z));
    truth.push_back(sway(t));
  }
  return out;
}

TEST(RepeatedMeasurements, ASourceReadFasterIsTakenAfterTwoRegularBlocks) {
  // 60 Hz read at 250 Hz: each measurement 4 or 5 times. Repeating once two blocks of runs have
  // ended, and each repeat (not the measurement) is said to be one.
  std::vector<Quat> truth;
  const std::vector<Sample> in = read_faster(60.0, 250.0, 3.0, 0.01, 1, truth);
  RepeatedMeasurements r;
  int runs = 0, repeats = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const bool repeat = r.note(in[i]);
    const bool new_measurement = i == 0 || !(in[i].orientation.coeffs() == in[i - 1].orientation.coeffs());
    EXPECT_EQ(repeat, !new_measurement) << i;
    repeats += repeat ? 1 : 0;
    if (new_measurement && i > 0) ++runs;  // a run ended
    EXPECT_EQ(r.repeating(), runs >= kRepeatBlocks * kRepeatBlockRuns) << "after " << runs << " runs";
  }
  EXPECT_GT(repeats, static_cast<int>(in.size()) * 2 / 3);
}

TEST(RepeatedMeasurements, AQuantisedSensorsChanceRepeatsAreMeasurements) {
  // A still sensor whose value stays the same at random (1 time in 3 up to 9 in 10): its runs
  // are as long as chance makes them, and it is never taken for a source read faster.
  for (const double p : {1.0 / 3.0, 0.5, 2.0 / 3.0, 0.8, 0.9}) {
    SCOPED_TRACE(p);
    std::mt19937_64 rng(7);
    std::bernoulli_distribution same(p);
    RepeatedMeasurements r;
    Quat q = Quat::Identity();
    int repeats = 0;
    for (int i = 0; i < 200000; ++i) {
      if (i > 0 && !same(rng)) q = (q * so3::exp(random_offset(rng, 1e-3))).normalized();
      repeats += r.note(at(i * 0.01, q)) ? 1 : 0;
      ASSERT_FALSE(r.repeating()) << "sample " << i;
    }
    EXPECT_NEAR(repeats / 200000.0, p, 0.01);  // the stream did repeat, by chance
  }
}

TEST(RepeatedMeasurements, ASourceWhoseReportsComeEarlyOrLateIsTakenToo) {
  // A 60 Hz source whose reports each come up to 3 ms early or late (uniform), read at 250 Hz:
  // runs of 2 to 6 samples, which the steady rule alone refuses (it did until 2026-12-06).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> late(-0.003, 0.003);
  std::vector<double> report;
  for (int k = 0; k < 600; ++k) report.push_back(k / 60.0 + late(rng));
  RepeatedMeasurements r;
  std::size_t k = 0;
  int repeating = 0, samples = 0;
  for (int i = 0; i < 2500; ++i) {
    const double t = i / 250.0;
    while (k + 1 < report.size() && report[k + 1] <= t) ++k;
    r.note(at(t, so3::exp(Vec3(0.01 * static_cast<double>(k), 0.0, 0.0))));
    if (t >= 2.0) {
      ++samples;
      repeating += r.repeating() ? 1 : 0;
    }
  }
  EXPECT_EQ(repeating, samples);  // from 2 s on (two blocks: 1.1 s)
}

TEST(RepeatedMeasurements, NothingRepeatsInAStreamOfMeasurementsOrOfInertialReadings) {
  RepeatedMeasurements r;
  std::vector<Quat> truth;
  for (const Sample& s : read_faster(250.0, 250.0, 2.0, 0.01, 2, truth)) EXPECT_FALSE(r.note(s));
  EXPECT_FALSE(r.repeating());
  // The same orientation each time, but each sample with a gyro reading of its own.
  RepeatedMeasurements g;
  for (int i = 0; i < 500; ++i) {
    Sample s = at(i * 0.004, Quat::Identity());
    s.flags |= kHasGyro;
    EXPECT_FALSE(g.note(s));
  }
  EXPECT_FALSE(g.repeating());
}

TEST(RepeatedMeasurements, ASourceThatStallsEndsTheRepeatingAtOnce) {
  std::vector<Quat> truth;
  const std::vector<Sample> in = read_faster(60.0, 250.0, 3.0, 0.01, 3, truth);
  RepeatedMeasurements r;
  for (const Sample& s : in) r.note(s);
  ASSERT_TRUE(r.repeating());
  // The last measurement again and again: past twice the longest run (5) and one more.
  Sample s = in.back();
  int repeats = 0;
  while (r.repeating()) {
    s.time += 0.004;
    ASSERT_TRUE(r.note(s));
    ASSERT_LT(++repeats, 12);
  }
  EXPECT_GE(repeats, 7);
}

// The engine on the sway measured at 60 Hz and read at 250 Hz, from 3 s on (after the
// repeating is taken and the window has filled at the source's rate).
struct Scored {
  double error = 0.0, raw = 0.0;
  std::uint64_t repeated = 0;
  EngineState state;
};
Scored score(const WindowConfig& config, const std::vector<Sample>& in, const std::vector<Quat>& truth) {
  FairingWindow w(config);
  std::vector<FairedPose> out(static_cast<std::size_t>(w.max_outputs_per_push()));
  double sq = 0.0, sq_raw = 0.0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const int k = w.push(in[i], out);
    EXPECT_EQ(k, config.lag == 0 ? 1 : k);
    if (in[i].time < 3.0 || k == 0) continue;
    sq += std::pow(so3::rotation_angle(out[static_cast<std::size_t>(k - 1)].orientation, truth[i]), 2);
    sq_raw += std::pow(so3::rotation_angle(in[i].orientation, truth[i]), 2);
  }
  return {std::sqrt(sq), std::sqrt(sq_raw), w.counters().repeated, w.state()};
}

TEST(RepeatedMeasurementsInTheEngine, AStreamReadFasterThanItsSourceIsFairedAtTheSourcesRate) {
  // Read at 250 Hz, the repeats hide the noise and the steps read as motion: the engine with
  // the stream's rate given (which keeps every sample in the window) is within 15% of raw. At the
  // source's rate, with the repeats carried forward, it gains what it gains on the source.
  for (const double noise : {0.002, 0.01}) {
    SCOPED_TRACE(noise);
    std::vector<Quat> truth;
    const std::vector<Sample> in = read_faster(60.0, 250.0, 12.0, noise, 4, truth);
    WindowConfig given;
    given.rate_hz = 250.0;
    const Scored a = score(WindowConfig{}, in, truth), b = score(given, in, truth);
    EXPECT_TRUE(a.state.repeating);
    EXPECT_NEAR(a.state.rate_hz, 60.0, 4.0);  // the median interval: 4 samples of 250 Hz
    EXPECT_GT(a.repeated, in.size() * 2 / 3);
    EXPECT_FALSE(b.state.repeating);
    EXPECT_EQ(b.repeated, 0u);
    EXPECT_GT(b.error, 0.85 * b.raw);  // measured 0.88 and 0.90
    EXPECT_LT(a.error, 0.75 * a.raw);  // 0.35 and 0.67: the engine's gain on this sway at 60 Hz
  }
}

TEST(RepeatedMeasurementsInTheEngine, ARepeatIsCarriedForwardWithinItsBoundAndItsStep) {
  // Every pose within ε of what was measured, rotation and position, each pose's step the time
  // since the one before, and a repeat carried on from the poses before for at most one of the
  // source's intervals: a source that stalls (here 0.2 s) is held, not extrapolated.
  std::vector<Quat> truth;
  std::vector<Sample> in = read_faster(60.0, 250.0, 6.0, 0.01, 5, truth);
  const std::size_t stall = 4 * 250;
  for (std::size_t i = stall + 1; i < stall + 50; ++i) in[i].orientation = in[stall].orientation;
  for (Sample& s : in) {  // a position measured with each orientation (and repeated with it)
    s.position = 100.0 * so3::log(s.orientation);
    s.flags |= kHasPosition;
  }
  WindowConfig c;
  c.epsilon_r = 0.004;
  c.epsilon_t = 0.4;
  FairingWindow w(c);
  std::vector<FairedPose> out(1);
  std::vector<FairedPose> poses;
  std::vector<char> repeating;
  for (const Sample& s : in) {
    ASSERT_EQ(w.push(s, out), 1);
    poses.push_back(out[0]);
    repeating.push_back(w.state().repeating ? 1 : 0);
    EXPECT_LE(so3::dist(out[0].orientation, out[0].measured), c.epsilon_r + 1e-12);
    EXPECT_LE((out[0].position - out[0].measured_position).norm(), c.epsilon_t + 1e-9);
  }
  EXPECT_GT(w.counters().repeated, 0u);
  EXPECT_GT(w.counters().clamped, 0u);  // the bound did bind
  for (std::size_t i = 1; i < poses.size(); ++i) EXPECT_NEAR(poses[i].step, in[i].time - in[i - 1].time, 1e-9) << i;
  // From one interval of the source (5 samples) into the stall on, the pose stands, until a run
  // over twice the longest (5) and one ends the repeating: then the repeats are measurements.
  ASSERT_TRUE(repeating[stall + 10]);
  EXPECT_FALSE(repeating[stall + 11]);
  for (std::size_t i = stall + 6; i <= stall + 10; ++i) {
    EXPECT_LT(so3::rotation_angle(poses[i].orientation, poses[stall + 5].orientation), 1e-12) << i;
    EXPECT_LT((poses[i].position - poses[stall + 5].position).norm(), 1e-9) << i;
  }
  EXPECT_GT(so3::rotation_angle(poses[stall + 1].orientation, poses[stall].orientation), 0.0);
  EXPECT_GT((poses[stall + 1].position - poses[stall].position).norm(), 0.0);
  EXPECT_TRUE(repeating.back());  // and taken again after
}

TEST(RepeatedMeasurementsInTheEngine, WithALagTheRepeatsStayInTheWindow) {
  std::vector<Quat> truth;
  const std::vector<Sample> in = read_faster(60.0, 250.0, 4.0, 0.01, 6, truth);
  WindowConfig c;
  c.lag = 2;
  const Scored a = score(c, in, truth);
  EXPECT_FALSE(a.state.repeating);
  EXPECT_EQ(a.repeated, 0u);
  EXPECT_NEAR(a.state.rate_hz, 250.0, 1.0);
}

}  // namespace
}  // namespace posefair
