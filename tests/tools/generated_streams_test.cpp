// tools/generated_streams.cpp: the streams of `posefair bench streams`, here the resampled ones
// (a tracker polled faster than it updates, a log put on another clock) and those with dropouts.
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "generated_streams.hpp"
#include "posefair/core/so3.hpp"

namespace posefair::tools {
namespace {

// Samples whose increment to the next equals the next one's (the same rotation twice running,
// to rounding): a slerp at equal steps between two measurements.
int equal_increments(const QualitySequence& s) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < s.input.size(); ++i) {
    const Vec3 a = so3::log(s.input.orientation[i].conjugate() * s.input.orientation[i + 1]);
    const Vec3 b = so3::log(s.input.orientation[i + 1].conjugate() * s.input.orientation[i + 2]);
    n += (a - b).norm() < 1e-9 * (1.0 + a.norm());
  }
  return n;
}

int changes(const QualitySequence& s) {
  int n = 0;
  for (std::size_t i = 0; i + 1 < s.input.size(); ++i) n += !s.input.orientation[i].coeffs().isApprox(s.input.orientation[i + 1].coeffs(), 0.0);
  return n;
}

TEST(GeneratedStreams, AHeldStreamChangesOnlyAtTheSourceRate) {
  const QualitySequence s = generated_stream({"sway", 250.0, 0.01, 20.0, 60.0, "hold"});
  EXPECT_EQ(s.name, "sway-250Hz-noise0.01-from60Hz-hold");
  ASSERT_EQ(s.input.size(), 5000u);
  EXPECT_DOUBLE_EQ(s.input.time[1], 1.0 / 250.0);
  // 20 s at 60 Hz: 1200 measurements, each new one once.
  EXPECT_NEAR(changes(s), 1199, 1);
}

TEST(GeneratedStreams, ALinearStreamSlerpsBetweenTheSourceMeasurements) {
  const QualitySequence linear = generated_stream({"walk", 250.0, 0.01, 20.0, 60.0, "linear"});
  const QualitySequence native = generated_stream({"walk", 250.0, 0.01, 20.0, 0.0, {}});
  // Between two measurements 1/60 s apart the stream takes equal steps. Every 0.1 s (25 samples,
  // 6 measurements) a measurement falls on a sample and breaks the one pair of increments around
  // it, and 5 fall between samples and break the two pairs that span each: 14 of every 25 of the
  // 4998 pairs are equal.
  EXPECT_NEAR(equal_increments(linear), 4998 * 14 / 25, 2);
  EXPECT_EQ(equal_increments(native), 0);
  EXPECT_EQ(changes(linear), 4999);
}

// What is kept is the stream without losses, sample for sample; what is lost comes in runs of
// `shortest` to `longest` samples, between `fewest` and `most` of them.
void expect_runs_lost(const QualitySequence& full, const QualitySequence& dropped, std::size_t shortest, std::size_t longest,
                      int fewest, int most) {
  ASSERT_EQ(dropped.input.size(), dropped.use.size());
  // What is kept is the stream without dropouts, sample for sample; what is lost comes in runs.
  std::size_t j = 0;
  int runs = 0;
  for (std::size_t i = 0; i < dropped.input.size(); ++i) {
    const std::size_t from = j;
    while (j < full.input.size() && full.input.time[j] < dropped.input.time[i]) ++j;
    ASSERT_LT(j, full.input.size());
    ASSERT_EQ(full.input.time[j], dropped.input.time[i]);
    EXPECT_TRUE(full.input.orientation[j].coeffs() == dropped.input.orientation[i].coeffs());
    EXPECT_EQ(full.use[j], dropped.use[i]);
    const std::size_t lost = j - from;
    if (lost > 0) {
      ++runs;
      EXPECT_GE(lost, shortest);
      EXPECT_LE(lost, longest);
    }
    ++j;
  }
  EXPECT_GE(runs, fewest);
  EXPECT_LE(runs, most);
}

TEST(GeneratedStreams, AStreamWithDropoutsLosesRunsOfFourToTwelveSamples) {
  const QualitySequence full = generated_stream({"turns", 120.0, 0.01, 20.0, 0.0, {}});
  const QualitySequence dropped = generated_stream({"turns", 120.0, 0.01, 20.0, 0.0, {}, 1.0});
  EXPECT_EQ(dropped.name, "turns-120Hz-noise0.01-dropouts");
  expect_runs_lost(full, dropped, 4, 12, 8, 35);  // one a second on average over 20 s
}

TEST(GeneratedStreams, AStreamThatLosesPacketsLosesOneOrTwoSamplesAtATime) {
  const QualitySequence full = generated_stream({"walk", 60.0, 0.01, 20.0, 0.0, {}});
  const QualitySequence lossy = generated_stream({"walk", 60.0, 0.01, 20.0, 0.0, {}, 0.0, 5.0});
  EXPECT_EQ(lossy.name, "walk-60Hz-noise0.01-lost");
  expect_runs_lost(full, lossy, 1, 2, 70, 130);  // five a second on average over 20 s
}

TEST(GeneratedStreams, AStreamWithNoiseBurstsIsTheSameStreamWithItsNoiseFiveTimesAsLargeInThem) {
  const QualitySequence plain = generated_stream({"sway", 60.0, 0.002, 20.0, 0.0, {}});
  const QualitySequence bursts = generated_stream({"sway", 60.0, 0.002, 20.0, 0.0, {}, 0.0, 0.0, 5.0});
  EXPECT_EQ(bursts.name, "sway-60Hz-noise0.002-bursts");
  ASSERT_EQ(bursts.input.size(), plain.input.size());
  int in_bursts = 0;
  for (std::size_t i = 0; i < plain.input.size(); ++i) {
    const double t = plain.input.time[i];
    ASSERT_EQ(bursts.input.time[i], t);
    const double phase = std::fmod(t, 5.0);
    if (phase >= 3.0 && phase < 4.0) {
      ++in_bursts;
      Quat truth;
      std::size_t cursor = 0;
      ASSERT_TRUE(plain.truth.at(t, truth, cursor));
      const double e_plain = so3::rotation_angle(truth, plain.input.orientation[i]);
      const double e_bursts = so3::rotation_angle(truth, bursts.input.orientation[i]);
      // (The truth is interpolated on a dense grid, within about 3e-7 rad of the exact one.)
      EXPECT_NEAR(e_bursts, 5.0 * e_plain, 3e-6) << t;
    } else {
      EXPECT_EQ(bursts.input.orientation[i].coeffs(), plain.input.orientation[i].coeffs()) << t;
    }
  }
  EXPECT_EQ(in_bursts, 4 * 60);  // 3–4, 8–9, 13–14, 18–19 s
}

TEST(GeneratedStreams, AnUnknownResamplingIsAnError) {
  EXPECT_THROW(generated_stream({"still", 250.0, 0.01, 5.0, 60.0, "cubic"}), std::invalid_argument);
}

}  // namespace
}  // namespace posefair::tools
