// Lone outliers (core/include/posefair/core/outlier_guard.hpp): the guard on its own (what it
// holds, what it takes, what it releases), and in the engine (held at the prediction with a lag,
// emitted as measured at lag 0, the ε bound still on the measurement, positions as well as
// rotations).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "engine_test_support.hpp"
#include "posefair/core/engine_setting.hpp"
#include "posefair/core/fairing_window.hpp"
#include "posefair/core/outlier_guard.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {
namespace {

using Verdict = OutlierGuard::Verdict;

// Feeds the guard the points x (steps dt) as the engine does: each increment from the value the
// window kept for the point before (the prediction where that was held, the measurement where it
// was released). Returns the verdicts.
std::vector<Verdict> feed(OutlierGuard& guard, const std::vector<Vec3>& x, double dt) {
  std::vector<Verdict> verdicts;
  Vec3 kept = x[0];
  for (std::size_t i = 1; i < x.size(); ++i) {
    Vec3 increment = x[i] - kept;
    const Verdict v = guard.check(dt, increment);
    verdicts.push_back(v);
    if (v == Verdict::Release) kept = x[i - 1];
    kept += increment;
    if (v != Verdict::Hold) {
      EXPECT_LT((kept - x[i]).norm(), 1e-12) << i;
    }
  }
  return verdicts;
}

// A line in three dimensions with Gaussian noise σ, at 100 Hz.
std::vector<Vec3> noisy_line(std::size_t n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < n; ++i)
    x.push_back(Vec3(0.3, -0.1, 0.05) * (static_cast<double>(i) * 0.01) + Vec3(noise(rng), noise(rng), noise(rng)));
  return x;
}

std::size_t count(const std::vector<Verdict>& v, Verdict which) {
  return static_cast<std::size_t>(std::count(v.begin(), v.end(), which));
}

TEST(OutlierGuard, HoldsALoneOutlierAtThePredictionAndTakesTheSampleAfterIt) {
  std::vector<Vec3> x = noisy_line(400, 0.001, 1);
  x[300] += Vec3(0.03, 0.0, -0.02);  // 36 σ off
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  Vec3 kept = x[0];
  for (std::size_t i = 1; i < x.size(); ++i) {
    Vec3 increment = x[i] - kept;
    const Verdict v = guard.check(0.01, increment);
    kept += increment;
    if (i == 300) {
      EXPECT_EQ(v, Verdict::Hold);
      // Held on the line: within a few σ of where the samples were going, not at the outlier.
      EXPECT_LT((kept - Vec3(0.3, -0.1, 0.05) * 3.0).norm(), 0.005);
    } else {
      EXPECT_EQ(v, Verdict::Take) << i;  // noise alone, and the sample after the outlier
    }
  }
}

TEST(OutlierGuard, NothingIsHeldUnderNoiseAlone) {
  // Ten thousand samples of Gaussian noise on a line, at several sizes: the threshold sits at
  // about 17 σ of each component (8 times the median of the prediction's error).
  for (const double sigma : {1e-3, 0.01, 0.1}) {
    OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
    const auto v = feed(guard, noisy_line(10000, sigma, 2), 0.01);
    EXPECT_EQ(count(v, Verdict::Take), v.size()) << sigma;
  }
}

TEST(OutlierGuard, AJumpThatStaysIsTakenBackWithTheSampleAfterIt) {
  // A jump (a relocalised SLAM estimate, a motion that starts at once) is held for one sample,
  // then released: the next sample lands nearer the held measurement than the line.
  std::vector<Vec3> x = noisy_line(400, 0.001, 3);
  for (std::size_t i = 300; i < x.size(); ++i) x[i] += Vec3(0.0, 0.05, 0.0);
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 0.01);
  EXPECT_EQ(v[298], Verdict::Take);
  EXPECT_EQ(v[299], Verdict::Hold);  // x[300]
  EXPECT_EQ(v[300], Verdict::Release);
  EXPECT_EQ(count(v, Verdict::Hold), 1u);
  EXPECT_EQ(count(v, Verdict::Release), 1u);
}

TEST(OutlierGuard, TwoFarSamplesAlikeAreAJumpNotABurst) {
  // Two far samples in a row, the second near the first: no different from a jump that stays (or
  // a motion's first samples), so the first is released and the second taken.
  std::vector<Vec3> x = noisy_line(400, 0.001, 4);
  x[300] += Vec3(0.05, 0.0, 0.0);
  x[301] += Vec3(0.05, 0.0, 0.0);
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 0.01);
  EXPECT_EQ(v[299], Verdict::Hold);
  EXPECT_EQ(v[300], Verdict::Release);
  EXPECT_EQ(count(v, Verdict::Hold), 1u);
}

TEST(OutlierGuard, AfterAReleaseNothingIsHeldUntilTheStepHasLeftTheLine) {
  // Three samples thrown the same way (a marker swapped for three frames): the first is held and
  // released by the second, as a jump's would be. The line then runs through that step and
  // overshoots the plateau, so the return from it lands far off the line; it is not taken for
  // an outlier (held, it would have been released by the next sample anyway, but with a lag the
  // burst's last pose had gone out against the line's overshoot).
  std::vector<Vec3> x = noisy_line(400, 0.001, 10);
  for (std::size_t i = 300; i < 303; ++i) x[i] += Vec3(0.02, 0.0, 0.0);
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 0.01);
  EXPECT_EQ(v[299], Verdict::Hold);
  EXPECT_EQ(v[300], Verdict::Release);
  EXPECT_EQ(v[302], Verdict::Take);  // x[303], back on the line
  EXPECT_EQ(count(v, Verdict::Hold), 1u);
  // A lone outlier once the step has left the line is held again.
  std::vector<Vec3> y = x;
  y[310] += Vec3(0.0, 0.05, 0.0);
  OutlierGuard again(kDefaultOutlierThreshold, 1.0);
  const auto w = feed(again, y, 0.01);
  EXPECT_EQ(w[309], Verdict::Hold);
}

TEST(OutlierGuard, ABurstOfUpToThreeOutliersIsHeldAndTheFourthTaken) {
  // Outliers in a row, each far from the line and from the one before (a tracker glitching for a
  // few frames): each is held while the sample before was held too, up to kMaxHeldRun; the
  // sample after them, back on the line, is taken and the held ones stay held.
  const std::vector<Vec3> off = {Vec3(0.05, 0.0, 0.0), Vec3(0.0, 0.05, 0.0), Vec3(0.0, 0.0, 0.05), Vec3(-0.05, 0.0, 0.0)};
  for (std::size_t run = 1; run <= off.size(); ++run) {
    SCOPED_TRACE(::testing::Message() << run << " in a row");
    std::vector<Vec3> x = noisy_line(400, 0.001, 8);
    for (std::size_t j = 0; j < run; ++j) x[300 + j] += off[j];
    OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
    const auto v = feed(guard, x, 0.01);
    const std::size_t held = std::min<std::size_t>(run, 3);  // kMaxHeldRun
    for (std::size_t j = 0; j < held; ++j) EXPECT_EQ(v[299 + j], Verdict::Hold) << j;
    EXPECT_EQ(v[299 + run], Verdict::Take);  // back on the line, or the fourth
    EXPECT_EQ(count(v, Verdict::Hold), held);
    EXPECT_EQ(count(v, Verdict::Release), 0u);
  }
}

TEST(OutlierGuard, TheLastOfABurstIsReleasedWhenTheSamplesAfterItFollowIt) {
  // An outlier, then a jump that stays: the outlier stays held, the jump's first sample is held
  // (far from the line and from the outlier) and released by the next, which lands near it.
  std::vector<Vec3> x = noisy_line(400, 0.001, 9);
  x[300] += Vec3(0.0, 0.0, 0.05);
  for (std::size_t i = 301; i < x.size(); ++i) x[i] += Vec3(0.05, 0.0, 0.0);
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 0.01);
  EXPECT_EQ(v[299], Verdict::Hold);
  EXPECT_EQ(v[300], Verdict::Hold);
  EXPECT_EQ(v[301], Verdict::Release);
  EXPECT_EQ(count(v, Verdict::Hold), 2u);
  EXPECT_EQ(count(v, Verdict::Release), 1u);
}

TEST(OutlierGuard, AFastMotionSlowingDownIsReleasedByItsNextSample) {
  // A quick turn at 60 Hz, 0.167 rad a sample, that starts to slow down: its first slower sample
  // falls behind the line and is held; the next goes on from it at about the line's pace, but
  // lands nearer the line than the held measurement (the step itself is 0.1 rad), and was held
  // as a burst's second sample, emitted at the line's prediction at lag 0, 0.09 rad off. It goes on
  // from the held measurement as the line goes on from the prediction: a motion, released.
  std::vector<Vec3> x = noisy_line(400, 0.001, 13);
  const Vec3 direction = Vec3(0.6, -0.64, 0.48);  // unit
  Vec3 along = Vec3::Zero();
  for (std::size_t i = 1; i < x.size(); ++i) {
    const double slowing = i < 300 ? 0.0 : 0.03 * static_cast<double>(i - 299);
    along += std::max(0.0, 0.167 - slowing) * direction;
    x[i] += along;
  }
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 1.0 / 60.0);
  EXPECT_EQ(count(v, Verdict::Hold) - count(v, Verdict::Release), 0u) << "nothing stays held";
  ASSERT_EQ(v[299], Verdict::Hold);     // x[300]: 0.03 rad behind the line
  EXPECT_EQ(v[300], Verdict::Release);  // x[301]: 0.09 behind it, 0.107 from the held one (held before)
}

TEST(OutlierGuard, HoldsNothingWhileWarmingUpOrOff) {
  std::vector<Vec3> x = noisy_line(400, 0.001, 5);
  x[10] += Vec3(0.05, 0.0, 0.0);   // before the median is trusted
  x[300] += Vec3(0.05, 0.0, 0.0);
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  auto v = feed(guard, x, 0.01);
  EXPECT_EQ(v[9], Verdict::Take);
  EXPECT_EQ(v[299], Verdict::Hold);
  OutlierGuard off(0.0, 1.0);
  v = feed(off, x, 0.01);
  EXPECT_EQ(count(v, Verdict::Take), v.size());
}

TEST(OutlierGuard, AFrozenStretchLeavesTheMedianAsItWas) {
  // A tracker that repeats its last value for two seconds (it sees nothing), then goes on from
  // where the motion is by then. The repeats are no new measurements: learnt from, they brought
  // the median down towards nothing, and once the stream moved again its noise was held (and
  // released) for a hundred samples or so. Now only the jump back onto the motion is held, and
  // released by the sample after it.
  const std::vector<Vec3> line = noisy_line(800, 0.001, 11);
  std::vector<Vec3> x = line;
  for (std::size_t i = 300; i < 500; ++i) x[i] = x[299];
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 0.01);
  EXPECT_EQ(v[499], Verdict::Hold);  // x[500]: the jump
  EXPECT_EQ(v[500], Verdict::Release);
  EXPECT_EQ(count(v, Verdict::Hold), 1u);
  EXPECT_EQ(count(v, Verdict::Release), 1u);
}

TEST(OutlierGuard, AQuantisedStillStreamHoldsNothing) {
  // Still, and quantised: its prediction error is zero nearly always, so the percentile is zero;
  // a least bit it moves now and then is under the floor, not an outlier.
  std::vector<Vec3> x(2000, Vec3::Zero());
  for (std::size_t i = 100; i < x.size(); i += 97) x[i] = Vec3(3e-5, 0.0, 0.0);
  OutlierGuard guard(kDefaultOutlierThreshold, 1.0);
  const auto v = feed(guard, x, 0.01);
  EXPECT_EQ(count(v, Verdict::Take), v.size());
}

// A still orientation (and position) at 100 Hz with noise, 1% of its samples thrown off.
struct StillWithOutliers {
  std::vector<Sample> samples;
  std::vector<std::size_t> outliers;
};
StillWithOutliers still_with_outliers(bool with_position, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  StillWithOutliers s;
  for (std::size_t i = 0; i < 2000; ++i) {
    Sample x;
    x.time = static_cast<double>(i) * 0.01;
    Vec3 r(noise(rng), noise(rng), noise(rng));
    Vec3 p(noise(rng), noise(rng), noise(rng));
    if (i > 50 && u(rng) < 0.01) {
      s.outliers.push_back(i);
      r += Vec3(0.1, -0.1, 0.05);
      p += Vec3(-0.1, 0.05, 0.1);
    }
    x.orientation = so3::from_rotation_vector(r);
    if (with_position) {
      x.position = p;
      x.flags |= kHasPosition;
    }
    s.samples.push_back(x);
  }
  return s;
}

double rotation_rms(const std::vector<FairedPose>& out) {
  double sum = 0.0;
  for (const FairedPose& p : out) sum += std::pow(so3::rotation_angle(p.orientation, Quat::Identity()), 2);
  return std::sqrt(sum / static_cast<double>(out.size()));
}

double position_rms(const std::vector<FairedPose>& out) {
  double sum = 0.0;
  for (const FairedPose& p : out) sum += p.position.squaredNorm();
  return std::sqrt(sum / static_cast<double>(out.size()));
}

TEST(OutlierGuardInTheEngine, OnByDefaultAndAsGiven) {
  WindowConfig c;
  EXPECT_EQ(outlier_threshold(c), kDefaultOutlierThreshold);
  c.lag = 1;
  EXPECT_EQ(outlier_threshold(c), kDefaultOutlierThreshold);
  c.outlier_threshold = 0.0;
  EXPECT_EQ(outlier_threshold(c), 0.0);
  c.lag = 0;
  c.outlier_threshold = 5.0;
  EXPECT_EQ(outlier_threshold(c), 5.0);
  c.outlier_threshold = -1.0;
  EXPECT_THROW(validate(c), InvalidEngineSetting);
  // The iterative solvers at lag 0 would emit a held sample at its prediction: off unless given.
  WindowConfig iterative;
  iterative.solver = WindowSolver::GaussNewton;
  EXPECT_EQ(outlier_threshold(iterative), 0.0);
  iterative.lag = 1;
  EXPECT_EQ(outlier_threshold(iterative), kDefaultOutlierThreshold);
}

TEST(OutlierGuardInTheEngine, WithALagAStillStreamsOutliersAreHeldAndFlagged) {
  const StillWithOutliers in = still_with_outliers(true, 6);
  ASSERT_GE(in.outliers.size(), 10u);
  WindowConfig on;
  on.lag = 1;
  WindowConfig off = on;
  off.outlier_threshold = 0.0;
  FairingWindow w(on);
  const auto guarded = run(w, in.samples);
  const auto plain = run(off, in.samples);
  ASSERT_EQ(guarded.size(), in.samples.size());
  // Nine in ten outliers held at least (one is not when the sample before it was not ordinary, or
  // was another outlier), each flagged on its pose, which still reports what was measured;
  // nothing else.
  EXPECT_GE(w.counters().held, in.outliers.size() * 9 / 10);
  EXPECT_LE(w.counters().released, 2u);  // two outliers in a row: the first is released
  std::size_t flagged = 0;
  for (std::size_t i = 0; i < guarded.size(); ++i) {
    const bool outlier = std::find(in.outliers.begin(), in.outliers.end(), i) != in.outliers.end();
    if (guarded[i].flags & kHeld) {
      EXPECT_TRUE(outlier) << i;
      ++flagged;
    }
    EXPECT_LT(so3::dist(guarded[i].measured, in.samples[i].orientation), 1e-12);
  }
  EXPECT_EQ(flagged, w.counters().held - w.counters().released);
  // The outliers no longer break the rest: a fraction of the error, rotation and position alike
  // (0.59 and 0.60 on this seed, whose outliers 930–932 come three in a row: the guard takes
  // them, and at lag 1 the sample after them, far from the line through them, is held until the
  // next one releases it, which pulls the last outlier's pose towards it; 0.42 at most
  // on seeds 7–11).
  EXPECT_LT(rotation_rms(guarded), 0.7 * rotation_rms(plain));
  EXPECT_LT(position_rms(guarded), 0.7 * position_rms(plain));
}

TEST(OutlierGuardInTheEngine, AtLagZeroAnOutlierIsEmittedAsMeasuredAndLeftOutOfThePosesAfterIt) {
  // At lag 0 the pose of a held sample goes out before the next sample can say whether it was an
  // outlier or a motion's start, so it is the pose the engine emits without the guard; from the
  // next pose on the window holds the prediction instead, and the outlier no longer breaks the
  // rest (at 100 Hz the rest line averages over a second).
  StillWithOutliers in = still_with_outliers(true, 7);
  const std::size_t at = in.outliers.front();
  const StillWithOutliers clean = in;
  for (std::size_t i = at + 1; i < in.samples.size(); ++i)  // one outlier only
    if (std::find(in.outliers.begin(), in.outliers.end(), i) != in.outliers.end()) {
      in.samples[i].orientation = in.samples[i - 1].orientation;
      in.samples[i].position = in.samples[i - 1].position;
    }
  FairingWindow w{WindowConfig{}};
  const auto guarded = run(w, in.samples);
  WindowConfig off;
  off.outlier_threshold = 0.0;
  const auto plain = run(off, in.samples);
  EXPECT_EQ(w.counters().held, 1u);
  EXPECT_EQ(w.counters().released, 0u);
  for (std::size_t i = 0; i <= at; ++i) {
    EXPECT_LT(so3::dist(guarded[i].orientation, plain[i].orientation), 1e-12) << i;
    EXPECT_LT((guarded[i].position - plain[i].position).norm(), 1e-12) << i;
    EXPECT_EQ(guarded[i].flags & kHeld, 0u) << i;
  }
  const std::vector<FairedPose> after_on(guarded.begin() + static_cast<std::ptrdiff_t>(at) + 1, guarded.begin() + static_cast<std::ptrdiff_t>(at) + 101);
  const std::vector<FairedPose> after_off(plain.begin() + static_cast<std::ptrdiff_t>(at) + 1, plain.begin() + static_cast<std::ptrdiff_t>(at) + 101);
  EXPECT_LT(rotation_rms(after_on), 0.5 * rotation_rms(after_off));
  EXPECT_LT(position_rms(after_on), 0.5 * position_rms(after_off));
  // On the whole stream with its 1% of outliers (each emitted as measured): less error too.
  FairingWindow all{WindowConfig{}};
  const auto guarded_all = run(all, clean.samples);
  EXPECT_GE(all.counters().held, clean.outliers.size() * 9 / 10);
  const auto plain_all = run(off, clean.samples);
  EXPECT_LT(rotation_rms(guarded_all), 0.8 * rotation_rms(plain_all));
  EXPECT_LT(position_rms(guarded_all), 0.8 * position_rms(plain_all));
}

// A still orientation and position at 100 Hz with noise, and bursts of two or three outliers, each
// thrown its own way (a tracker glitching for a few frames), or all of a burst the same way
// (a marker swapped for a few frames).
StillWithOutliers still_with_bursts(std::uint64_t seed, bool same_way = false) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::normal_distribution<double> glitch(0.0, 0.1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  StillWithOutliers s;
  int burst = 0;
  Vec3 r_off = Vec3::Zero(), p_off = Vec3::Zero();
  for (std::size_t i = 0; i < 3000; ++i) {
    Sample x;
    x.time = static_cast<double>(i) * 0.01;
    Vec3 r(noise(rng), noise(rng), noise(rng));
    Vec3 p(noise(rng), noise(rng), noise(rng));
    if (burst == 0 && i > 50 && (s.outliers.empty() || i > s.outliers.back() + 10) && u(rng) < 0.01)
      burst = u(rng) < 0.5 ? 2 : 3;
    if (burst > 0) {
      if (!same_way || s.outliers.empty() || s.outliers.back() + 1 != i) {
        r_off = Vec3(glitch(rng), glitch(rng), glitch(rng));
        p_off = Vec3(glitch(rng), glitch(rng), glitch(rng));
      }
      --burst;
      s.outliers.push_back(i);
      r += r_off;
      p += p_off;
    }
    x.orientation = so3::from_rotation_vector(r);
    x.position = p;
    x.flags |= kHasPosition;
    s.samples.push_back(x);
  }
  return s;
}

TEST(OutlierGuardInTheEngine, ABurstOfOutliersIsHeldWhole) {
  // Up to three outliers in a row are held (each far from the line and from the one before):
  // with a lag their poses are the prediction's, flagged; at lag 0 the first goes out as
  // measured and the rest at the prediction, flagged, and the poses after them are left alone.
  // (Before bursts were held, the second of two was taken and bent the line.)
  const StillWithOutliers in = still_with_bursts(13);
  ASSERT_GE(in.outliers.size(), 40u);
  WindowConfig off;
  off.outlier_threshold = 0.0;
  for (const int lag : {0, 1}) {
    SCOPED_TRACE(::testing::Message() << "lag " << lag);
    WindowConfig on;
    on.lag = lag;
    off.lag = lag;
    FairingWindow w(on);
    const auto guarded = run(w, in.samples);
    const auto plain = run(off, in.samples);
    ASSERT_EQ(guarded.size(), in.samples.size());
    // 57 of 68 (28 when only a sample after an ordinary one was held); the rest come after a
    // sample that was not ordinary, or within five samples of a release. 12 of the 57 are released
    // (the next landed nearer them than the line, as a motion's second sample does).
    EXPECT_GE(w.counters().held, in.outliers.size() * 8 / 10);
    std::size_t flagged = 0;
    for (std::size_t i = 0; i < guarded.size(); ++i) {
      if (guarded[i].flags & kHeld) {
        EXPECT_TRUE(std::find(in.outliers.begin(), in.outliers.end(), i) != in.outliers.end()) << i;
        ++flagged;
      }
    }
    if (lag == 0) {
      // Only the rest of a burst (its first sample goes out as measured).
      for (std::size_t i = 1; i < guarded.size(); ++i) {
        if (guarded[i].flags & kHeld) {
          EXPECT_TRUE(std::find(in.outliers.begin(), in.outliers.end(), i - 1) != in.outliers.end()) << i;
        }
      }
      EXPECT_GT(flagged, 0u);
      EXPECT_LT(flagged, w.counters().held - w.counters().released);
    } else {
      // Counted per sample: a release may take back one channel and leave the other held.
      EXPECT_LE(flagged, w.counters().held);
      EXPECT_GE(flagged, w.counters().held - w.counters().released);
    }
    // Rotation and position against the guard-free engine: at lag 0 0.69 and 0.84 (0.87 and
    // 0.91 before bursts were held, 0.79 and 0.88 with the rest of a burst emitted as measured),
    // at lag 1 0.58 and 0.73 (0.83 and 0.82). On 2026-12-06 the rotation's at lag 0 went to 0.75
    // with the changes at rest that day and to 0.76 with a motion's stop taken at once
    // (docs/engine.md), which brought the guard-free engine's error down more than the guarded
    // one's (0.0181 → 0.0179 rad against 0.01358 → 0.01351).
    EXPECT_LT(rotation_rms(guarded), (lag == 0 ? 0.8 : 0.7) * rotation_rms(plain));
    EXPECT_LT(position_rms(guarded), (lag == 0 ? 0.87 : 0.78) * position_rms(plain));
  }
}

TEST(OutlierGuardInTheEngine, ABurstHoldingOneValueCostsNothingWithALag) {
  // A burst of two or three samples thrown the same way is taken, as a jump that stays is (its
  // second sample releases the first). At lag 0 every pose is the guard-free engine's; at lag 1
  // the return from it is not held either (the line runs through the burst's step), so the
  // burst's last pose goes out against the return, not against the line's overshoot (before:
  // 1.07 and 1.08 times the guard-free error in rotation and position on this stream; now 0.97).
  const StillWithOutliers in = still_with_bursts(14, true);
  ASSERT_GE(in.outliers.size(), 40u);
  for (const int lag : {0, 1}) {
    SCOPED_TRACE(::testing::Message() << "lag " << lag);
    WindowConfig on;
    on.lag = lag;
    WindowConfig off = on;
    off.outlier_threshold = 0.0;
    FairingWindow w(on);
    const auto guarded = run(w, in.samples);
    const auto plain = run(off, in.samples);
    ASSERT_EQ(guarded.size(), plain.size());
    EXPECT_GT(w.counters().held, 10u);
    if (lag == 0) {
      for (std::size_t i = 0; i < guarded.size(); ++i) {
        ASSERT_LT(so3::dist(guarded[i].orientation, plain[i].orientation), 1e-12) << i;
        ASSERT_LT((guarded[i].position - plain[i].position).norm(), 1e-12) << i;
      }
    } else {
      EXPECT_LT(rotation_rms(guarded), rotation_rms(plain));
      EXPECT_LT(position_rms(guarded), position_rms(plain));
    }
  }
}

TEST(OutlierGuardInTheEngine, TheBoundIsOnTheMeasurementOfAHeldSample) {
  // ε promises every output within ε of its measurement, an outlier's too: a held sample's pose
  // is projected onto the ball around what was measured, not around the prediction.
  const StillWithOutliers in = still_with_outliers(true, 8);
  WindowConfig c;
  c.lag = 1;
  c.epsilon_r = 0.02;
  c.epsilon_t = 0.03;
  FairingWindow w(c);
  const auto out = run(w, in.samples);
  EXPECT_GE(w.counters().held, in.outliers.size() * 9 / 10);
  std::size_t clamped_held = 0;
  for (const FairedPose& p : out) {
    EXPECT_LE(so3::dist(p.orientation, p.measured), c.epsilon_r * (1.0 + 1e-9));
    EXPECT_LE((p.position - p.measured_position).norm(), c.epsilon_t * (1.0 + 1e-9));
    if ((p.flags & kHeld) && (p.flags & kClamped)) ++clamped_held;
  }
  EXPECT_EQ(clamped_held, w.counters().held - w.counters().released);
}

TEST(OutlierGuardInTheEngine, AGyroAidedWindowIsNotGuarded) {
  // Its residuals and bias estimate keep every increment, so a release could not take a held
  // one back: the same still stream with a (still) gyroscope on every sample holds nothing.
  StillWithOutliers in = still_with_outliers(false, 10);
  WindowConfig c;
  c.lag = 1;
  FairingWindow plain(c);
  run(plain, in.samples);
  EXPECT_GE(plain.counters().held, in.outliers.size() * 9 / 10);
  for (Sample& s : in.samples) {
    s.gyro = Vec3::Zero();
    s.flags |= kHasGyro;
  }
  FairingWindow aided(c);
  run(aided, in.samples, false);
  EXPECT_TRUE(aided.state().gyro.active);
  EXPECT_EQ(aided.counters().held, 0u);
}

TEST(OutlierGuardInTheEngine, AQuickTurnsStartIsReleasedAndFollowedAsWithoutTheGuard) {
  // 60° in 0.1 s at 60 Hz, from still, with little noise: its first sample is as far off the
  // line as an outlier. With a lag the next sample releases it before it is emitted, so no pose
  // is held and the turn is followed as without the guard. At lag 0 the held sample is emitted
  // as measured, and the release puts the adaptation back as it was before the hold and lets it
  // learn from the measurement: every pose is the guard-free engine's, to rounding.
  const double rate = 60.0;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0.0, 0.003);
  std::vector<Sample> in;
  std::vector<Quat> truth;
  for (int i = 0; i < 20 * static_cast<int>(rate); ++i) {
    const double t = i / rate;
    double yaw = 0.0;
    for (int k = 0; k < 10; ++k) {
      const double u = std::clamp((t - 1.0 - 2.0 * k - 0.3 * std::sin(static_cast<double>(k))) / 0.1, 0.0, 1.0);
      yaw += (k % 2 ? -1.0 : 1.0) * std::numbers::pi / 3.0 * u * u * (3.0 - 2.0 * u);
    }
    truth.push_back(so3::from_rotation_vector(Vec3(0.0, 0.0, yaw)));
    Sample s;
    s.time = t;
    s.orientation = truth.back() * so3::from_rotation_vector(Vec3(noise(rng), noise(rng), noise(rng)));
    in.push_back(s);
  }
  for (const int lag : {0, 1}) {
    SCOPED_TRACE(lag);
    WindowConfig on;
    on.lag = lag;
    WindowConfig off = on;
    off.outlier_threshold = 0.0;
    FairingWindow w(on);
    const auto guarded = run(w, in);
    const auto plain = run(off, in);
    EXPECT_GT(w.counters().held, 0u);
    EXPECT_EQ(w.counters().released, w.counters().held);
    double e_on = 0.0, e_off = 0.0;
    for (std::size_t i = 0; i < guarded.size(); ++i) {
      EXPECT_EQ(guarded[i].flags & kHeld, 0u) << i;
      if (lag == 0) {
        EXPECT_LT(so3::dist(guarded[i].orientation, plain[i].orientation), 1e-12) << i;
      }
      e_on += std::pow(so3::rotation_angle(guarded[i].orientation, truth[i]), 2);
      e_off += std::pow(so3::rotation_angle(plain[i].orientation, truth[i]), 2);
    }
    EXPECT_LT(e_on, 1.02 * e_off);
  }
}

TEST(OutlierGuardInTheEngine, AHostileStreamKeepsEveryPromise) {
  // Outliers alone, in pairs and in threes (each thrown its own way, or all by one offset), sudden turns, gaps, a change of rate, positions that
  // come and go, a tracker that freezes and jumps: at lags 0, 1 and 3, and with a horizon (at
  // lag 0), every sample is emitted once and in order, every pose is finite and (without a
  // horizon, which has no ε) within ε of what was measured, and at lag 0 only the rest of a
  // burst is emitted held. (The holds and releases take the adaptation's copies and replays
  // through every path the window has; under ASan too.)
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0.0, 0.004);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Sample> in;
  double t = 0.0, yaw = 0.0, rate = 100.0;
  int burst = 0;
  bool scattered = false;  // each sample of the burst thrown its own way, or all by one offset
  Vec3 burst_off = Vec3::Zero(), frozen_r = Vec3::Zero();
  for (int i = 0; i < 3000; ++i) {
    if (i == 1500) rate = 50.0;
    t += (i % 400 == 399) ? 0.3 : 1.0 / rate;  // a gap now and then
    if (u(rng) < 0.01) yaw += 0.5;              // a sudden turn that stays
    if (burst == 0 && u(rng) < 0.03) {
      burst = 1 + static_cast<int>(u(rng) * 3.0);
      scattered = u(rng) < 0.5;
      burst_off = Vec3(0.2 * u(rng), -0.15, 0.1 * u(rng));
    } else if (burst > 0 && scattered) {
      burst_off = Vec3(0.2 * u(rng), 0.3 * u(rng) - 0.15, -0.1 * u(rng));
    }
    const bool frozen = (i / 100) % 7 == 3;  // the tracker repeats its last value
    Vec3 r = Vec3(0.02 * std::sin(t), 0.01 * std::cos(2.0 * t), yaw + 0.1 * std::sin(0.5 * t)) +
             Vec3(noise(rng), noise(rng), noise(rng));
    if (frozen) r = frozen_r;
    frozen_r = r;
    if (burst > 0) {
      r += burst_off;
      --burst;
    }
    Sample s;
    s.time = t;
    s.sequence = static_cast<std::uint64_t>(i);
    s.orientation = so3::from_rotation_vector(r);
    if ((i / 700) % 2 == 0) {
      s.position = Vec3(0.1 * std::sin(t), 0.0, 1.0) + 0.01 * r;
      s.flags |= kHasPosition;
    }
    in.push_back(s);
  }
  std::vector<std::size_t> flagged_at_lag_0, flagged_at_lag_1;
  for (const int lag : {0, 1, 3}) {
    for (const double horizon : {0.0, 0.02}) {
      if (lag > 0 && horizon > 0.0) continue;  // a prediction is emitted at once
      SCOPED_TRACE(::testing::Message() << "lag " << lag << " horizon " << horizon);
      WindowConfig c;
      c.lag = lag;
      c.horizon_s = horizon;
      if (horizon == 0.0) {
        c.epsilon_r = 0.05;
        c.epsilon_t = 0.02;
      }
      FairingWindow w(c);
      const auto out = run(w, in);
      EXPECT_GT(w.counters().held, 20u);
      EXPECT_GT(w.counters().released, 5u);
      ASSERT_EQ(out.size(), in.size());
      for (std::size_t i = 0; i < out.size(); ++i) {
        const FairedPose& p = out[i];
        ASSERT_EQ(p.sequence, i);
        ASSERT_TRUE(p.orientation.coeffs().allFinite()) << i;
        ASSERT_TRUE(p.position.allFinite()) << i;
        EXPECT_LE(so3::dist(p.orientation, p.measured), c.epsilon_r * (1.0 + 1e-9)) << i;
        if (in[i].has_position()) {
          EXPECT_LE((p.position - p.measured_position).norm(), c.epsilon_t * (1.0 + 1e-9)) << i;
        }
        if ((p.flags & kHeld) && horizon == 0.0 && lag <= 1) (lag == 0 ? flagged_at_lag_0 : flagged_at_lag_1).push_back(i);
      }
    }
  }
  // At lag 0 only the rest of a burst goes out held: a sample held after a held one it did not
  // release, which therefore stays held and goes out so with a lag (the guard decides alike at
  // every lag; the sample itself may be released by the next, after lag 0 has emitted it).
  EXPECT_GT(flagged_at_lag_0.size(), 0u);
  EXPECT_LT(flagged_at_lag_0.size(), flagged_at_lag_1.size());
  for (const std::size_t i : flagged_at_lag_0)
    EXPECT_TRUE(std::binary_search(flagged_at_lag_1.begin(), flagged_at_lag_1.end(), i - 1)) << i;
}

}  // namespace
}  // namespace posefair
