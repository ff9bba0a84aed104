#pragma once
// Helpers shared by the pose file tests: reading files back, a scratch directory per test,
// the error a text raises, and exact comparison of pose sequences.
#include <gtest/gtest.h>

#include <string>

#include "../support/test_files.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {

using ::posefair::testing::slurp;

// The small pose files the format tests read (tests/formats/data/).
inline const std::string kData = POSEFAIR_SOURCE_DIR "/tests/formats/data/";

// A fresh scratch directory for the running test, named after it
// ("posefair_<Suite>_<Test>_XXXXXX", e.g. posefair_TumFormat_FreshFileRoundTrips_a1B2c3),
// removed at the end.
class TempDir : public ::posefair::testing::ScratchDir {
 public:
  TempDir() : ScratchDir(prefix_for_current_test()) {}

 private:
  static std::string prefix_for_current_test() {
    std::string prefix = "posefair_";
    if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info())
      prefix += std::string(info->test_suite_name()) + "_" + info->name() + "_";
    for (char& c : prefix)
      if (c == '/') c = '_';  // parameterised tests: "Instance/Suite", "Name/0"
    return prefix;
  }
};

// Options that read a text as `format` (instead of deciding by the file name).
inline ReadOptions read_as(PoseFormat format) {
  ReadOptions o;
  o.format = format;
  return o;
}

// The error that parsing `text` as file `name` raises, or a test failure when it raises none.
inline PoseFileError parse_error(const std::string& text, const std::string& name, const ReadOptions& options) {
  try {
    parse_pose_text(text, name, options);
  } catch (const PoseFileError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return PoseFileError("", 0, "");
}

// Same size, and bit-identical times, quaternion coefficients and positions (if any).
inline void expect_identical(const PoseSequence& a, const PoseSequence& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.position.size(), b.position.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a.time[k], b.time[k]) << k;
    ASSERT_EQ(a.orientation[k].coeffs(), b.orientation[k].coeffs()) << k;
    if (a.has_position()) {
      ASSERT_EQ(a.position[k], b.position[k]) << k;
    }
  }
}

}  // namespace posefair::formats
