// The continuity weight κ feeds emitted poses back into later ones; the engine refuses
// settings whose recursion diverges (spectral radius ≥ 1) and accepted ones stay bounded.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "posefair/core/causal_fairing.hpp"
#include "posefair/core/quality_metrics.hpp"
#include "posefair/core/synthetic_motion.hpp"

namespace posefair {
namespace {

TEST(ContinuityStability, ThirdOrderWithStrongContinuityIsRefused) {
  WindowConfig c;
  c.order = 3;
  c.window = 32;
  c.smoothing_r = c.smoothing_t = 1e4;
  c.continuity = 100.0;
  try {
    FairingWindow w(c);
    FAIL() << "expected the unstable configuration to be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("unstable"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("spectral radius"));
  }
}

TEST(ContinuityStability, AcceptedContinuityStaysBoundedOverALongStream) {
  SyntheticMotionSpec spec;
  spec.samples = 20000;
  spec.sample_rate_hz = 1000.0;
  spec.cycles = 10.0;
  spec.rotation_noise = 0.02;
  spec.with_position = false;
  const auto motion = make_synthetic_motion(spec);
  for (int m : {2, 3}) {
    WindowConfig c;
    c.order = m;
    c.window = 32;
    c.smoothing_r = c.smoothing_t = smoothing_for_cutoff(4.0, 1000.0, m);
    c.continuity = 1.0;
    ASSERT_NO_THROW(FairingWindow{c});
    const auto r = fair_causal(motion.noisy, c);
    const ErrorStats e = rotation_error(r.poses.orientation, motion.truth.orientation);
    EXPECT_LT(e.max, 0.05) << "m=" << m;  // noise is < 0.04 rad physical; no growth
    EXPECT_LT(e.rms, 0.02) << "m=" << m;
  }
}

}  // namespace
}  // namespace posefair
