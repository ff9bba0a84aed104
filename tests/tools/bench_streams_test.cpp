// `posefair bench streams`: the defaults on generated streams against raw and the best
// configuration of each family picked on each stream itself.
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::q;
using testing::run_posefair;
using testing::ScratchDir;

std::vector<std::string> fields(const std::string& line) {
  // CSV with quoted configuration texts (which hold no commas or quotes of their own).
  std::vector<std::string> out(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back().push_back(c);
  }
  return out;
}

TEST(BenchStreams, TheDefaultsBeatRawOnEveryQuickStreamAndTheBestIsNoWorseThanTheDefault) {
  ScratchDir dir;
  const auto r = run_posefair("bench streams --quick -o " + q(dir.path()), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("## Generated streams: the defaults where nothing was tuned"));
  EXPECT_THAT(r.out, HasSubstr("| turns-100Hz-noise0.01 |"));
  EXPECT_THAT(r.out, HasSubstr("- above raw by more than 1%: 0 of 4"));
  std::istringstream csv(testing::slurp(dir / "streams.csv"));
  std::string line;
  std::getline(csv, line);
  ASSERT_EQ(line,
            "stream,motion,rate_hz,noise,raw,default,one_euro_default,best_posefair,best_posefair_config,best_one_euro,"
            "best_one_euro_config,raw_jitter,default_jitter,source_hz,resampling,dropouts_per_s,lost_per_s,burst_factor");
  int rows = 0;
  while (std::getline(csv, line)) {
    const auto f = fields(line);
    ASSERT_EQ(f.size(), 18u) << line;
    EXPECT_EQ(f[13], "0") << "measured at its own rate";
    EXPECT_EQ(f[14], "");
    EXPECT_EQ(f[15], "0") << "no dropouts";
    EXPECT_EQ(f[16], "0") << "no lost packets";
    EXPECT_EQ(f[17], "0") << "no noise bursts";
    SCOPED_TRACE(f[0]);
    const double raw = std::stod(f[4]), fair = std::stod(f[5]), best = std::stod(f[7]);
    // Sway and turns at 30 and 100 Hz under noise of 0.01 rad: 4–36% below raw (measured).
    EXPECT_LT(fair, raw);
    // The default is one of posefair's configurations, run again: each run's delivery times
    // add its own measured processing time, so under load the two differ in the last digits
    // (a run of ctest beside a benchmark failed this by comparing them exactly).
    EXPECT_LE(best, fair * (1.0 + 1e-4)) << "the default is one of posefair's configurations";
    EXPECT_LT(std::stod(f[12]), std::stod(f[11])) << "jitter";
    ++rows;
  }
  EXPECT_EQ(rows, 4);
}

}  // namespace
}  // namespace posefair
