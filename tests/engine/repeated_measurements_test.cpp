// A stream read faster than its source updates (repeated_measurements.hpp): how it is told from
// a quantised sensor's chance repeats, and what the engine makes of it. And one slerped from a
// slower source (slerped_measurements.hpp): how its measurements are found, and what the engine
// makes of it.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/fairing_window.hpp"
#include "posefair/core/repeated_measurements.hpp"
#include "posefair/core/slerped_measurements.hpp"
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
// each sample the newest measurement taken at or before its time, or with `slerped` the slerp
// between it and the next (a log put on another clock). truth: the sway at each sample's time;
// measured: the measurements, the k-th at k / source_hz.
std::vector<Sample> read_faster(double source_hz, double rate_hz, double seconds, double noise, std::uint64_t seed,
                                std::vector<Quat>& truth, bool slerped = false, std::vector<Quat>* measured = nullptr) {
  std::mt19937_64 rng(seed);
  std::vector<Quat> z;
  const auto measurement = [&](long k) {
    while (static_cast<long>(z.size()) <= k)
      z.push_back((sway(static_cast<double>(z.size()) / source_hz) * so3::exp(random_offset(rng, noise))).normalized());
    return z[static_cast<std::size_t>(k)];
  };
  std::vector<Sample> out;
  truth.clear();
  for (long i = 0; i < std::lround(seconds * rate_hz); ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    const long k = static_cast<long>(std::floor(t * source_hz + 1e-9));
    const double f = std::max(0.0, t * source_hz - static_cast<double>(k));
    out.push_back(at(t, slerped && f > 0.0 ? so3::slerp(f, measurement(k), measurement(k + 1)) : measurement(k)));
    truth.push_back(sway(t));
  }
  if (measured != nullptr) *measured = z;
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
  std::uint64_t repeated = 0, interpolated = 0;
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
  return {std::sqrt(sq), std::sqrt(sq_raw), w.counters().repeated, w.counters().interpolated, w.state()};
}

// Pushes each sample (one pose each, at lag 0), checks the pose within ε of its sample, rotation
// and position, and returns the poses; after_each is called after each push.
template <class AfterEach>
std::vector<FairedPose> bounded_poses(FairingWindow& w, const WindowConfig& c, const std::vector<Sample>& in, AfterEach&& after_each) {
  std::vector<FairedPose> out(1);
  std::vector<FairedPose> poses;
  for (const Sample& s : in) {
    EXPECT_EQ(w.push(s, out), 1);
    poses.push_back(out[0]);
    after_each();
    EXPECT_LE(so3::dist(out[0].orientation, out[0].measured), c.epsilon_r + 1e-12);
    EXPECT_LE((out[0].position - out[0].measured_position).norm(), c.epsilon_t + 1e-9);
  }
  return poses;
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
  std::vector<char> repeating;
  const std::vector<FairedPose> poses = bounded_poses(w, c, in, [&] { repeating.push_back(w.state().repeating ? 1 : 0); });
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

// How far the repeats move from the pose emitted for their measurement, against the steps
// between the measurements' poses (RMS, from 3 s on): carried whole, a repeat at a quarter to
// four fifths of the source's interval moves about half a step.
struct Carried {
  double step = 0.0, carried = 0.0;
};
Carried carried_from_measurements(const std::vector<Sample>& in) {
  FairingWindow w(WindowConfig{});
  std::vector<FairedPose> out(1);
  Quat measured_pose = Quat::Identity();
  double steps = 0.0, carried = 0.0;
  int n_steps = 0, n_carried = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(w.push(in[i], out), 1);
    const bool repeat = i > 0 && in[i].orientation.coeffs() == in[i - 1].orientation.coeffs();
    if (in[i].time >= 3.0) {
      const double d = so3::rotation_angle(measured_pose, out[0].orientation);
      (repeat ? carried : steps) += d * d;
      ++(repeat ? n_carried : n_steps);
    }
    if (!repeat) measured_pose = out[0].orientation;
  }
  EXPECT_TRUE(w.state().repeating);
  return {std::sqrt(steps / n_steps), std::sqrt(carried / n_carried)};
}

TEST(RepeatedMeasurementsInTheEngine, ARepeatCarriesOnOnlyAStepClearOfTheNoise) {
  // A still tracker read faster than it updates: the steps between its poses are the noise
  // left in them, and carried on they would add it again (measured, carried whole: 0.54–0.62 of
  // a step, and the repeats 4–9% over the measurements' error). Under the Wiener weight the
  // repeats stay near the pose (0.02–0.36 of a step on seeds 1–3). A sway's steps stand clear of
  // the noise and are carried whole.
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    std::vector<Sample> still;
    std::mt19937_64 rng(seed);
    Quat z = Quat::Identity();
    for (int i = 0; i < 12 * 250; ++i) {
      const double t = i / 250.0;
      if (i == 0 || std::floor(t * 60.0 + 1e-9) != std::floor((i - 1) / 250.0 * 60.0 + 1e-9)) z = so3::exp(random_offset(rng, 0.01)).normalized();
      still.push_back(at(t, z));
    }
    const Carried c = carried_from_measurements(still);
    EXPECT_LT(c.carried, 0.45 * c.step);
    std::vector<Quat> truth;
    const Carried s = carried_from_measurements(read_faster(60.0, 250.0, 12.0, 0.002, seed, truth));
    EXPECT_GT(s.carried, 0.5 * s.step);
  }
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

// Each measurement a slerped stream reports is the source's next one, at its time, exactly (to
// rounding), once its lines' kinks have come regularly for two blocks of 32; not where the source
// is over a third of the rate (a line needs two equal steps after its kink).
// Clean streams too, whose kink at a measurement is now and then within rounding of none: the
// measurement is then found on the grid of the source's intervals.
TEST(SlerpedMeasurements, AStreamSlerpedFromASlowerSourceIsTakenWithItsMeasurements) {
  for (const double rate_hz : {250.0, 1000.0})
  for (const double source_hz : {30.0, 60.0, 80.0, 90.0, 250.0})
    for (const double noise : {0.0002, 0.01}) {
      if (source_hz > rate_hz / 2.0 || (rate_hz > 500.0 && source_hz < 60.0)) continue;
      SCOPED_TRACE(testing::Message() << source_hz << " Hz at " << rate_hz << " Hz, noise " << noise);
      std::vector<Quat> truth, measured;
      const double seconds = rate_hz > 500.0 ? 3.0 : 8.0;
      const std::vector<Sample> in = read_faster(source_hz, rate_hz, seconds, noise, 7, truth, true, &measured);
      SlerpedMeasurements m;
      long found = 0, taken_at = -1;
      for (std::size_t i = 0; i < in.size(); ++i) {
        SlerpKnot next;
        if (m.note(in[i], next)) {
          ++found;
          const double k = next.time * source_hz;
          ASSERT_NEAR(k, std::round(k), 1e-6) << i;
          ASSERT_LT(so3::dist(next.orientation, measured[static_cast<std::size_t>(std::lround(k))]), 1e-9) << i;
          EXPECT_GT(next.time, in[i].time);  // ahead of the sample that confirms its line
        }
        if (m.slerped() && taken_at < 0) taken_at = static_cast<long>(i);
      }
      if (source_hz > rate_hz / kMinSlerpRun) {
        EXPECT_FALSE(m.slerped());
        EXPECT_EQ(found, 0);
        continue;
      }
      const double per_run = rate_hz / source_hz;
      EXPECT_NEAR(taken_at, (kRepeatBlocks * kRepeatBlockRuns + 1) * per_run, 2.0 * per_run);  // from the first knot
      EXPECT_TRUE(m.slerped());
      EXPECT_GE(found, std::lround((seconds - static_cast<double>(taken_at) / rate_hz) * source_hz) - 2);
    }
}

// A measured stream, however clean, and one that repeats its measurements are not slerped; nor is
// a stream with inertial readings. A slerped stream that turns into measurements stops being
// slerped within a few of its runs.
TEST(SlerpedMeasurements, MeasuredAndRepeatedStreamsAreNotSlerped) {
  std::vector<Quat> truth;
  for (const double noise : {0.0, 1e-5, 0.0002, 0.01}) {
    SCOPED_TRACE(noise);
    SlerpedMeasurements measured, held, inertial;
    const std::vector<Sample> at_1k = read_faster(1000.0, 1000.0, 4.0, noise, 8, truth);
    const std::vector<Sample> repeats = read_faster(60.0, 250.0, 4.0, noise, 9, truth);
    SlerpKnot next;
    for (const Sample& s : at_1k) {
      EXPECT_FALSE(measured.note(s, next));
      Sample g = s;
      g.flags |= kHasGyro;
      EXPECT_FALSE(inertial.note(g, next));
    }
    for (const Sample& s : repeats) EXPECT_FALSE(held.note(s, next));
    EXPECT_FALSE(measured.slerped());
    EXPECT_FALSE(held.slerped());
    EXPECT_FALSE(inertial.slerped());
  }
  std::vector<Sample> in = read_faster(60.0, 250.0, 6.0, 0.01, 10, truth, true);
  const std::vector<Sample> after = read_faster(250.0, 250.0, 6.0, 0.01, 11, truth);
  std::copy(after.begin() + 1000, after.end(), in.begin() + 1000);
  SlerpedMeasurements m;
  SlerpKnot next;
  for (std::size_t i = 0; i < 1000; ++i) m.note(in[i], next);
  ASSERT_TRUE(m.slerped());
  for (std::size_t i = 1000; i < 1012; ++i) m.note(in[i], next);
  EXPECT_FALSE(m.slerped());  // a run over twice the longest (5) and one
}

// The sway of the tests above measured at 60 Hz and slerped to 250 Hz: passed through before, as
// nothing predicts its coloured noise better than its own samples; faired at the source's rate,
// each sample interpolated between the poses faired for the measurements about it.
TEST(SlerpedMeasurementsInTheEngine, AStreamSlerpedFromASlowerSourceIsFairedAtTheSourcesRate) {
  for (const double noise : {0.002, 0.01}) {
    SCOPED_TRACE(noise);
    std::vector<Quat> truth;
    const std::vector<Sample> in = read_faster(60.0, 250.0, 12.0, noise, 12, truth, true);
    WindowConfig given;
    given.rate_hz = 250.0;
    const Scored a = score(WindowConfig{}, in, truth), b = score(given, in, truth);
    EXPECT_TRUE(a.state.slerped);
    EXPECT_FALSE(a.state.repeating);
    EXPECT_NEAR(a.state.rate_hz, 60.0, 2.0);
    EXPECT_GT(a.interpolated, in.size() * 2 / 3);
    EXPECT_FALSE(b.state.slerped);
    EXPECT_EQ(b.interpolated, 0u);
    EXPECT_GT(b.error, 0.97 * b.raw);  // measured 1.00 and 1.00
    // Measured 0.95 and 0.84; faired at 60 Hz, the same sway measured at 60 Hz has 0.88 and 0.73 of
    // its raw error, but raw's between two measurements is their slerp, which averages their noise.
    EXPECT_LT(a.error, (noise < 0.005 ? 0.97 : 0.88) * a.raw);
  }
}

// Every pose within ε of its sample, rotation and position, and each pose's step the time since
// the one before, through the slerping's start.
TEST(SlerpedMeasurementsInTheEngine, EachSampleIsInterpolatedWithinItsBoundAndItsStep) {
  std::vector<Quat> truth, measured;
  std::vector<Sample> in = read_faster(60.0, 250.0, 6.0, 0.01, 13, truth, true, &measured);
  for (Sample& s : in) {  // a position measured with each orientation, and lerped as it is slerped
    const double at = s.time * 60.0;
    const auto k = static_cast<std::size_t>(std::floor(at + 1e-9));
    const double f = std::max(0.0, at - static_cast<double>(k));
    s.position = 100.0 * ((1.0 - f) * so3::log(measured[k]) + f * so3::log(measured[std::min(k + 1, measured.size() - 1)]));
    s.flags |= kHasPosition;
  }
  WindowConfig c;
  c.epsilon_r = 0.002;
  c.epsilon_t = 0.2;
  FairingWindow w(c);
  const std::vector<FairedPose> poses = bounded_poses(w, c, in, [] {});
  EXPECT_TRUE(w.state().slerped);
  EXPECT_GT(w.counters().interpolated, 0u);
  EXPECT_GT(w.counters().clamped, 0u);  // the bound did bind
  EXPECT_EQ(w.counters().emitted, in.size());
  for (std::size_t i = 1; i < poses.size(); ++i) EXPECT_NEAR(poses[i].step, in[i].time - in[i - 1].time, 1e-9) << i;
}

}  // namespace
}  // namespace posefair
