// Format dispatch, error text, writer argument checks and the atomic write.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pose_file_test_support.hpp"
#include "posefair/formats/atomic_write.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

void spit_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

TEST(PoseFile, FormatComesFromTheExtensionOrTheOptions) {
  EXPECT_EQ(format_from_extension("a/b.txt"), PoseFormat::Tum);
  EXPECT_EQ(format_from_extension("b.TUM"), PoseFormat::Tum);
  EXPECT_EQ(format_from_extension("b.Csv"), PoseFormat::Csv);
  EXPECT_EQ(format_from_extension("b.bvh"), PoseFormat::Bvh);
  EXPECT_FALSE(format_from_extension("b.dat").has_value());
  EXPECT_FALSE(format_from_extension("README").has_value());
  EXPECT_EQ(to_string(PoseFormat::Csv), "csv");

  EXPECT_EQ(read_pose_file(kData + "small.tum", {}).format(), PoseFormat::Tum);
  EXPECT_EQ(read_pose_file(kData + "small_wfirst.csv", {}).format(), PoseFormat::Csv);
  ReadOptions bvh;
  bvh.bvh_joint = "Spine";
  EXPECT_EQ(read_pose_file(kData + "small.bvh", bvh).format(), PoseFormat::Bvh);

  // An explicit format wins over the name.
  ReadOptions as_tum;
  as_tum.format = PoseFormat::Tum;
  EXPECT_EQ(parse_pose_text("1 0 0 0 0 0 0 1\n", "pose.log", as_tum).poses().size(), 1u);
  std::istringstream in("t,qw,qx,qy,qz\n0,1,0,0,0\n");
  EXPECT_EQ(parse_pose_file(in, "stream.csv", {}).format(), PoseFormat::Csv);
}

TEST(PoseFile, UnknownExtensionAndUnreadableFilesAreErrors) {
  try {
    read_pose_file("walk.dat", {});
    FAIL() << "no error";
  } catch (const PoseFileError& e) {
    EXPECT_EQ(e.path(), "walk.dat");
    EXPECT_EQ(e.line(), 0u);
    EXPECT_EQ(std::string(e.what()),
              "walk.dat:0: unknown pose file extension '.dat' (expected .txt, .tum, .csv or .bvh, "
              "or give the format explicitly)");
  }
  EXPECT_THAT([] { read_pose_file("/nonexistent/dir/walk.txt", {}); },
              ::testing::ThrowsMessage<PoseFileError>(
                  HasSubstr("/nonexistent/dir/walk.txt:0: cannot open: No such file or directory")));
  ReadOptions as_tum;
  as_tum.format = PoseFormat::Tum;
  EXPECT_THAT([&] { read_pose_file(kData, as_tum); },
              ::testing::ThrowsMessage<PoseFileError>(HasSubstr("cannot open: is a directory")));
}

TEST(PoseFile, ErrorTextIsPathLineMessage) {
  const PoseFileError e("walk.txt", 17, "field 3 'abc' is not a number");
  EXPECT_EQ(std::string(e.what()), "walk.txt:17: field 3 'abc' is not a number");
  EXPECT_EQ(e.path(), "walk.txt");
  EXPECT_EQ(e.line(), 17u);
  EXPECT_EQ(e.message(), "field 3 'abc' is not a number");
  const std::runtime_error& base = e;
  EXPECT_THAT(base.what(), HasSubstr("walk.txt:17:"));
}

TEST(PoseFile, WriterRejectsPosesThatDoNotFit) {
  TempDir dir;
  const PoseFile f = read_pose_file(kData + "small.tum", {});
  const fs::path out = dir.path() / "out.tum";
  PoseSequence shorter = f.poses();
  shorter.time.pop_back();
  shorter.orientation.pop_back();
  shorter.position.pop_back();
  EXPECT_THROW(write_pose_file(out, f, shorter), std::invalid_argument);

  PoseSequence backwards = f.poses();
  backwards.time[2] = 0.0;
  EXPECT_THROW(write_pose_file(out, f, backwards), std::invalid_argument);

  PoseSequence nan = f.poses();
  nan.position[1].y() = std::nan("");
  EXPECT_THROW(write_pose_file(out, f, nan), std::invalid_argument);

  PoseSequence zero = f.poses();
  zero.orientation[0] = Quat(0, 0, 0, 0);
  EXPECT_THROW(write_pose_file(out, f, zero), std::invalid_argument);
  EXPECT_TRUE(dir.entries().empty());  // nothing was written

  // Orientation-only poses keep the file's positions.
  PoseSequence orientation_only = f.poses();
  orientation_only.position.clear();
  orientation_only.orientation[0] = Quat(0, 1, 0, 0);
  write_pose_file(out, f, orientation_only);
  const PoseFile back = read_pose_file(out, {});
  EXPECT_EQ(back.poses().position, f.poses().position);
  EXPECT_EQ(back.poses().orientation[0].coeffs(), Quat(0, 1, 0, 0).coeffs());
}

TEST(AtomicWrite, MissingDirectoryThrowsAndLeavesNothing) {
  TempDir dir;
  const fs::path out = dir.path() / "no" / "such" / "dir" / "out.txt";
  const PoseFile f = read_pose_file(kData + "small.tum", {});
  try {
    write_pose_file(out, f, f.poses());
    FAIL() << "no error";
  } catch (const PoseFileError& e) {
    EXPECT_EQ(e.path(), out.string());
    EXPECT_EQ(e.line(), 0u);
    EXPECT_THAT(e.message(), HasSubstr("cannot create temporary file"));
    EXPECT_THAT(e.message(), HasSubstr("No such file or directory"));
  }
  EXPECT_FALSE(fs::exists(dir.path() / "no"));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicWrite, ReplacesAnExistingFileOnlyOnSuccess) {
  TempDir dir;
  const fs::path out = dir.path() / "walk.txt";
  spit_text(out, "old contents\n");
  ::chmod(out.c_str(), 0640);
  const PoseFile f = read_pose_file(kData + "small.tum", {});

  // A failure (the poses do not fit) leaves the old file as it was.
  PoseSequence bad = f.poses();
  bad.time.clear();
  EXPECT_THROW(write_pose_file(out, f, bad), std::invalid_argument);
  EXPECT_EQ(slurp(out), "old contents\n");

  // Success replaces it completely, keeps its permissions, and leaves no temporary file.
  write_pose_file(out, f, f.poses());
  EXPECT_EQ(slurp(out), slurp(kData + "small.tum"));
  struct stat st{};
  ASSERT_EQ(::stat(out.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"walk.txt"});
}

TEST(AtomicWrite, FailureAfterTheTemporaryFileExistsRemovesIt) {
  TempDir dir;
  // The target is a directory: the temporary file is created, then the write is refused.
  const fs::path target = dir.path() / "taken";
  fs::create_directory(target);
  spit_text(target / "inside", "x");
  EXPECT_THAT([&] { write_file_atomically(target, "new\n"); },
              ::testing::ThrowsMessage<PoseFileError>(HasSubstr("taken:0: not a regular file")));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"taken"});
  EXPECT_EQ(slurp(target / "inside"), "x");

  // A stale temporary file of a dead process with our pid does not block the write.
  const fs::path out = dir.path() / "out.csv";
  spit_text(out.string() + ".tmp." + std::to_string(::getpid()), "stale");
  write_file_atomically(out, "fresh\n");
  EXPECT_EQ(slurp(out), "fresh\n");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.csv", "taken"}));
}

}  // namespace
}  // namespace posefair::formats
