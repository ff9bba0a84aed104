// tools/quality_docs.py: each benchmark's tables (bench quality, bench streams) go between the
// document's markers for it, and nothing else in the document changes; a document it cannot
// update is refused before the benchmarks run, and a failed benchmark leaves it as it was.
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_runner.hpp"

namespace posefair {
namespace {

using ::testing::EndsWith;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;
using testing::q;
using testing::run_program;
using testing::ScratchDir;

const std::string kPython = "/usr/bin/python3";
const std::string kScript = POSEFAIR_SOURCE_DIR "/tools/quality_docs.py";
// A document as docs/benchmarks.md is laid out: hand-written text around two generated blocks.
const std::string kBefore = "# A document\n\nHand-written text before.\n\n## Results\n";
const std::string kQualityBegin = "<!-- posefair bench quality: begin -->\n";
const std::string kQualityEnd = "<!-- posefair bench quality: end -->\n";
const std::string kBetween = "\n### What loses, and why\nHand-written text between.\n\n## Generated streams\n";
const std::string kStreamsBegin = "<!-- posefair bench streams: begin -->\n";
const std::string kStreamsEnd = "<!-- posefair bench streams: end -->\n";
const std::string kAfter = "Read by hand.\n";

std::string document(const std::string& quality, const std::string& streams) {
  return kBefore + kQualityBegin + quality + kQualityEnd + kBetween + kStreamsBegin + streams + kStreamsEnd + kAfter;
}

testing::CliResult run_script(const ScratchDir& dir, const std::string& bench_args) {
  return run_program(kPython,
                     q(kScript) + " --posefair " + q(POSEFAIR_CLI_PROGRAM) + " --doc " + q(dir / "doc.md") + " -o " +
                         q(dir / "out") + " --no-plots --quick -- " + bench_args,
                     dir);
}

TEST(QualityDocs, PutsEachBenchmarksTablesBetweenItsMarkersAndLeavesTheRestAsItWas) {
  ScratchDir dir;
  testing::write_text(dir / "doc.md", document("an old table\n", "old streams\n"));
  auto r = run_script(dir, "");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string doc = testing::slurp(dir / "doc.md");
  EXPECT_THAT(doc, StartsWith(kBefore + "<!-- posefair bench quality: begin"));
  EXPECT_THAT(doc, HasSubstr(kQualityEnd + kBetween + "<!-- posefair bench streams: begin"));
  EXPECT_THAT(doc, EndsWith(kStreamsEnd + kAfter));
  EXPECT_THAT(doc, Not(HasSubstr("an old table")));
  EXPECT_THAT(doc, Not(HasSubstr("old streams")));
  // Each block: its stamp, then the benchmark's tables one heading level down (under the
  // document's "## Results"), without the benchmark's note of the files it wrote.
  const std::string quality = doc.substr(0, doc.find(kQualityEnd));
  EXPECT_THAT(quality, HasSubstr("What `posefair bench quality -o "));
  EXPECT_THAT(quality, HasSubstr("\n### Smoothing: every row scored on the report split\n"));
  EXPECT_THAT(quality, HasSubstr("\n#### synthetic-100Hz-noise0.01\n"));
  EXPECT_THAT(quality, HasSubstr("| posefair default | fixed |"));
  EXPECT_THAT(quality, HasSubstr("\n### Where posefair's defaults lose ("));
  EXPECT_THAT(doc, Not(HasSubstr("\nwrote ")));
  const std::string streams = doc.substr(doc.find("<!-- posefair bench streams: begin"));
  EXPECT_THAT(streams, HasSubstr("What `posefair bench streams -o "));
  EXPECT_THAT(streams, HasSubstr("\n### Generated streams: the defaults where nothing was tuned\n"));
  EXPECT_THAT(streams, HasSubstr("| sway-100Hz-noise0.01 |"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "quality-summary.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "streams" / "streams.csv"));

  // Run again: one block each still, replaced, not added to.
  r = run_script(dir, "");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  doc = testing::slurp(dir / "doc.md");
  EXPECT_EQ(doc.find("### Smoothing: every row"), doc.rfind("### Smoothing: every row"));
  EXPECT_EQ(doc.find("What `posefair bench streams"), doc.rfind("What `posefair bench streams"));
  EXPECT_THAT(doc, EndsWith(kStreamsEnd + kAfter));
}

TEST(QualityDocs, ADocumentWithoutItsMarkersIsRefusedBeforeTheBenchmarksRun) {
  ScratchDir dir;
  const std::string text = kBefore + "no markers here\n" + kBetween + kAfter;
  testing::write_text(dir / "doc.md", text);
  const auto r = run_script(dir, "");
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr((dir / "doc.md").string() + ": needs exactly one line starting '<!-- posefair bench quality: begin'"));
  EXPECT_EQ(testing::slurp(dir / "doc.md"), text);
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "a benchmark ran";

  // One block's markers are not enough, and markers in the wrong order are refused too.
  testing::write_text(dir / "doc.md", kBefore + kQualityBegin + kQualityEnd + kAfter);
  EXPECT_EQ(run_script(dir, "").exit_code, 65);
  testing::write_text(dir / "doc.md", kBefore + kQualityEnd + kQualityBegin + kBetween + kStreamsBegin + kStreamsEnd + kAfter);
  EXPECT_EQ(run_script(dir, "").exit_code, 65);
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "a benchmark ran";
}

TEST(QualityDocs, AFailedBenchmarkLeavesTheDocumentAsItWas) {
  ScratchDir dir;
  const std::string text = document("the last good tables\n", "the last good streams\n");
  testing::write_text(dir / "doc.md", text);
  const auto r = run_script(dir, "--set no-such-set");
  EXPECT_EQ(r.exit_code, 64) << "the benchmark's own exit status";
  EXPECT_THAT(r.err, HasSubstr("no data set or kind 'no-such-set'"));
  EXPECT_THAT(r.err, HasSubstr("doc.md is unchanged"));
  EXPECT_EQ(testing::slurp(dir / "doc.md"), text);
}

}  // namespace
}  // namespace posefair
