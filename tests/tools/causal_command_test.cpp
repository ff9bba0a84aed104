// `posefair fair --causal` runs the real-time engine over a file exactly as the daemon will:
// its output must equal the engine called directly, sample for sample, bit for bit.
#include <filesystem>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "posefair/core/causal_fairing.hpp"
#include "posefair/core/fairing_window.hpp"
#include "posefair/core/so3.hpp"
#include "posefair/core/synthetic_motion.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::run_posefair;
using testing::ScratchDir;

PoseSequence noisy(bool with_position) {
  SyntheticMotionSpec spec;
  spec.samples = 400;
  spec.rotation_noise = 0.03;
  spec.with_position = with_position;
  spec.cube_size = 2.0;
  spec.position_noise = 0.01;
  return make_synthetic_motion(spec).noisy;
}

struct Case {
  const char* options;
  WindowConfig config;
};

TEST(CausalCommand, EqualsTheEngineCalledDirectly) {
  WindowConfig linear;
  linear.order = 2;
  linear.window = 24;
  linear.lag = 3;
  linear.smoothing_r = linear.smoothing_t = 250.0;
  linear.continuity = 0.5;
  linear.epsilon_r = 0.02;
  linear.epsilon_t = 0.01;
  WindowConfig gn = linear;
  gn.solver = WindowSolver::GaussNewton;
  gn.iterations = 2;
  gn.order = 3;
  gn.bound = BoundPolicy::Window;
  WindowConfig predicted;
  predicted.horizon_s = 0.02;
  WindowConfig sweeps;
  sweeps.order = 3;
  sweeps.window = 16;
  sweeps.solver = WindowSolver::DampedSweeps;
  sweeps.iterations = 4;
  sweeps.lambda_r = 0.2;
  sweeps.lambda_t = 0.3;
  const Case cases[] = {
      {"-m 2 --window 24 --lag 3 --smoothing 250 --continuity 0.5 --eps-r 0.04 --eps-t 0.01", linear},
      {"-m 3 --window 24 --lag 3 --smoothing 250 --continuity 0.5 --eps-r 0.04 --eps-t 0.01 --solver gauss-newton "
       "--window-iterations 2 --bound window",
       gn},
      {"-m 3 --window 16 --solver sweeps --window-iterations 4 --lambda-r 0.2 --lambda-t 0.3", sweeps},
      {"", WindowConfig{}},  // the defaults: adapted smoothing, a 0.5 s window
      {"--horizon 0.02", predicted},
  };
  for (bool with_position : {false, true}) {
    for (const Case& c : cases) {
      ScratchDir dir;
      const PoseSequence in = noisy(with_position);
      const auto in_path = dir / "in.csv";
      formats::write_pose_file(in_path, formats::make_csv(in), in);
      const auto out_path = dir / "out.csv";
      const auto r = run_posefair("fair --causal '" + in_path.string() + "' -o '" + out_path.string() + "' " + c.options, dir);
      ASSERT_EQ(r.exit_code, 0) << r.err << c.options;
      EXPECT_THAT(r.out, HasSubstr("400 emitted"));
      // The file as the CLI read it (values round-trip exactly), through the engine directly.
      const PoseSequence read_back = formats::read_pose_file(in_path, {}).poses();
      // The engine measures the rate as for a live stream.
      const WindowConfig config = c.config;
      const CausalResult direct = fair_causal(read_back, config);
      const PoseSequence cli = formats::read_pose_file(out_path, {}).poses();
      ASSERT_EQ(cli.size(), direct.poses.size());
      for (std::size_t i = 0; i < cli.size(); ++i) {
        ASSERT_EQ(cli.orientation[i].coeffs(), direct.poses.orientation[i].coeffs()) << c.options << " sample " << i;
        // A prediction is stamped with the time it is for.
        ASSERT_NEAR(cli.time[i], read_back.time[i] + config.horizon_s, 1e-9) << c.options << " sample " << i;
        if (with_position) {
          ASSERT_EQ(cli.position[i], direct.poses.position[i]) << c.options << " sample " << i;
        }
      }
    }
  }
}

// A still stream at 100 Hz with three samples thrown 0.2 rad off: the outlier guard (on by
// default, docs/engine.md "Outliers") holds each, and the run says how it was guarded.
TEST(CausalCommand, SaysWhatTheOutlierGuardHeld) {
  ScratchDir dir;
  PoseSequence in;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (int i = 0; i < 500; ++i) {
    in.time.push_back(i * 0.01);
    const Vec3 off = i == 200 || i == 300 || i == 400 ? Vec3(0.2, 0.0, 0.0) : Vec3::Zero();
    in.orientation.push_back(so3::from_rotation_vector(off + Vec3(noise(rng), noise(rng), noise(rng))));
  }
  const auto in_path = dir / "in.csv";
  formats::write_pose_file(in_path, formats::make_csv(in), in);
  const std::string run = "fair --causal '" + in_path.string() + "' -o '" + (dir / "o.csv").string() + "'";
  auto r = run_posefair(run, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("outliers 3 held at the prediction (threshold 8; at lag 0 each emitted as measured, but the rest of a burst"));
  r = run_posefair(run + " --lag 1", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("outliers 3 held at the prediction (threshold 8), 0 of them released"));
  r = run_posefair(run + " --outlier-threshold 0", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("outliers not guarded (--outlier-threshold 0)"));
}

TEST(CausalCommand, CutoffNeedsTheFileRateAndWindowOptionsNeedCausal) {
  ScratchDir dir;
  const PoseSequence in = noisy(false);
  const auto in_path = dir / "in.csv";
  formats::write_pose_file(in_path, formats::make_csv(in), in);
  auto r = run_posefair("fair --causal '" + in_path.string() + "' -o '" + (dir / "o.csv").string() + "' --cutoff 80", dir);
  EXPECT_EQ(r.exit_code, 64);  // 80 Hz is above half the 100 Hz rate
  EXPECT_THAT(r.err, HasSubstr("cutoff"));
  r = run_posefair("fair '" + in_path.string() + "' -o '" + (dir / "o.csv").string() + "' --window 8", dir);
  EXPECT_EQ(r.exit_code, 64);
  r = run_posefair("fair --causal '" + in_path.string() + "' -o '" + (dir / "o.csv").string() + "' --bound window", dir);
  EXPECT_EQ(r.exit_code, 64);  // the linear solver has no window bound
  EXPECT_THAT(r.err, HasSubstr("iterative solver"));
  r = run_posefair("fair --causal '" + in_path.string() + "' -o '" + (dir / "o.csv").string() + "' --cutoff 4 --lag 2", dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("lag 2 (20 ms)"));
  // An iterative solver takes its smoothing at construction: a cutoff needs --rate (this aborted
  // on an uncaught exception before).
  r = run_posefair("fair --causal '" + in_path.string() + "' -o '" + (dir / "o.csv").string() +
                       "' --solver gauss-newton --window 32 --cutoff 5",
                   dir);
  EXPECT_EQ(r.exit_code, 64) << r.err;
  EXPECT_THAT(r.err, HasSubstr("rate_hz"));
  r = run_posefair("fair --causal '" + in_path.string() + "' -o '" + (dir / "o.csv").string() +
                       "' --solver gauss-newton --window 32 --cutoff 5 --rate 100",
                   dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(BenchQuality, QuickRunTunesOnTrainingSeedsAndReportsEveryRow) {
  ScratchDir dir;
  const auto r = run_posefair("bench quality --quick -o '" + dir.path().string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string runs = testing::slurp(dir / "quality-runs.csv");
  EXPECT_THAT(runs, HasSubstr("dataset,sequence,role,family,config,error_delivered,error_aligned,lag_ms"));
  for (const char* family : {",raw,", ",posefair-default,", ",one-euro-default,", ",posefair,", ",one-euro,", ",slerp,",
                             ",posefair-sweeps,"})
    EXPECT_THAT(runs, HasSubstr(family)) << family;
  // Tuned on seed 1, reported on seeds 2 and 3: the split is in the file, row by row.
  EXPECT_THAT(runs, HasSubstr("synthetic-100Hz-noise0.01,seed1,train,"));
  EXPECT_THAT(runs, HasSubstr("synthetic-100Hz-noise0.01,seed2,report,"));
  EXPECT_THAT(runs, Not(HasSubstr(",seed1,report,")));
  const std::string prediction = testing::slurp(dir / "quality-prediction-summary.csv");
  for (const char* row : {",10,dead-reckoning,", ",20,slerp-extrapolation,", ",30,one-euro-dr,", ",20,posefair-default,"})
    EXPECT_THAT(prediction, HasSubstr(row)) << row;
  EXPECT_THAT(r.out, HasSubstr("| posefair default | fixed |"));
  EXPECT_THAT(r.out, HasSubstr("| One Euro tuned | 10 ms |"));
  EXPECT_THAT(r.out, HasSubstr("Where posefair's defaults lose"));
  EXPECT_THAT(r.out, Not(HasSubstr("none fits")));  // every budget has a row of every tuned family
}

// --set runs one data set or kind alone; a name that is none of them is a usage error that
// lists what there is (here --quick: the synthetic set alone).
TEST(BenchQuality, SetNamesTheDataSetsToRun) {
  ScratchDir dir;
  const auto r = run_posefair("bench quality --quick --set broad -o '" + dir.path().string() + "'", dir);
  EXPECT_EQ(r.exit_code, 64);
  EXPECT_THAT(r.err, HasSubstr("no data set or kind 'broad'; there are: synthetic-100Hz-noise0.01"));
  EXPECT_FALSE(std::filesystem::exists(dir / "quality-runs.csv")) << "nothing runs after a usage error";
}

}  // namespace
}  // namespace posefair
