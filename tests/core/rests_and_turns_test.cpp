// RestsAndTurns: the benchmarks' resting and turning tracker keeps to its spec.
#include <random>

#include <gtest/gtest.h>

#include "posefair/core/rests_and_turns.hpp"

namespace posefair {
namespace {

TEST(RestsAndTurns, RestsAndTurnsLastAndTurnAsTheSpecSays) {
  RestsAndTurnsSpec spec;  // still 1–3 s, turned 20–90° in 0.3–0.8 s
  spec.seconds = 60.0;
  std::mt19937_64 rng(3);
  const RestsAndTurns motion(spec, rng);
  // Sampled every millisecond: a still stretch is a rest, a moving one a turn.
  constexpr double dt = 0.001;
  EXPECT_TRUE(motion.at(0.0).isApprox(Quat::Identity()));
  Quat previous = motion.at(0.0), turn_from = previous;
  bool moving = false;
  double since = 0.0;
  int turns = 0;
  for (double t = dt; t < spec.seconds + 1.0; t += dt) {
    const Quat q = motion.at(t);
    const bool now_moving = so3::rotation_angle(previous, q) > 1e-9;
    if (now_moving != moving) {
      const double lasted = t - since;
      if (now_moving) {
        // A rest (the first one from the start) ends.
        EXPECT_GE(lasted, spec.rest_min_s - 2.0 * dt) << t;
        EXPECT_LE(lasted, spec.rest_max_s + 2.0 * dt) << t;
        turn_from = previous;
      } else {
        EXPECT_GE(lasted, spec.turn_min_s - 2.0 * dt) << t;
        EXPECT_LE(lasted, spec.turn_max_s + 2.0 * dt) << t;
        const double angle = so3::rotation_angle(turn_from, previous) * 180.0 / std::numbers::pi;
        EXPECT_GE(angle, spec.angle_min_deg - 1e-6) << t;
        EXPECT_LE(angle, spec.angle_max_deg + 1e-6) << t;
        ++turns;
      }
      moving = now_moving;
      since = t;
    }
    previous = q;
  }
  EXPECT_FALSE(moving) << "the last turn ends";
  EXPECT_GE(turns, 15);  // 60 s of rests of 1–3 s and turns of 0.3–0.8 s
  EXPECT_LE(turns, 47);
}

TEST(RestsAndTurns, TheSameGeneratorStateGivesTheSameMotion) {
  std::mt19937_64 a(7), b(7);
  const RestsAndTurns first(RestsAndTurnsSpec{}, a), second(RestsAndTurnsSpec{}, b);
  for (double t = 0.0; t < 20.0; t += 0.01) EXPECT_TRUE(first.at(t).isApprox(second.at(t), 0.0)) << t;
  EXPECT_EQ(a(), b()) << "both drew as many numbers";
}

}  // namespace
}  // namespace posefair
