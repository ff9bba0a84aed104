// tools/quality_docs.py: the benchmark's tables go between the document's markers, and
// nothing else in the document changes; a document it cannot update is refused before the
// benchmark runs, and a failed benchmark leaves the document as it was.
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
const std::string kBegin = "<!-- posefair bench quality: begin -->\n";
const std::string kEnd = "<!-- posefair bench quality: end -->\n";
const std::string kBefore = "# A document\n\nHand-written text before.\n\n## Results\n";
const std::string kAfter = "\n### What loses, and why\nHand-written text after.\n";

testing::CliResult run_script(const ScratchDir& dir, const std::string& bench_args) {
  return run_program(kPython,
                     q(kScript) + " --posefair " + q(POSEFAIR_CLI_PROGRAM) + " --doc " + q(dir / "doc.md") + " -o " +
                         q(dir / "out") + " --no-plots -- " + bench_args,
                     dir);
}

TEST(QualityDocs, PutsTheTablesBetweenTheMarkersAndLeavesTheRestAsItWas) {
  ScratchDir dir;
  testing::write_text(dir / "doc.md", kBefore + kBegin + "an old table\n" + kEnd + kAfter);
  auto r = run_script(dir, "--quick");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string doc = testing::slurp(dir / "doc.md");
  EXPECT_THAT(doc, StartsWith(kBefore + "<!-- posefair bench quality: begin"));
  EXPECT_THAT(doc, EndsWith(kEnd + kAfter));
  EXPECT_THAT(doc, Not(HasSubstr("an old table")));
  // The stamp, then the benchmark's tables one heading level down (under the document's
  // "## Results"), without its note of the files it wrote.
  EXPECT_THAT(doc, HasSubstr("What `posefair bench quality -o "));
  EXPECT_THAT(doc, HasSubstr("\n### Smoothing: every row scored on the report split\n"));
  EXPECT_THAT(doc, HasSubstr("\n#### synthetic-100Hz-noise0.01\n"));
  EXPECT_THAT(doc, HasSubstr("| posefair default | fixed |"));
  EXPECT_THAT(doc, HasSubstr("\n### Where posefair's defaults lose ("));
  EXPECT_THAT(doc, Not(HasSubstr("\nwrote ")));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "quality-summary.csv"));

  // Run again: one block still, replaced, not added to.
  r = run_script(dir, "--quick");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  doc = testing::slurp(dir / "doc.md");
  EXPECT_EQ(doc.find("### Smoothing: every row"), doc.rfind("### Smoothing: every row"));
  EXPECT_EQ(doc.find("What `posefair bench quality"), doc.rfind("What `posefair bench quality"));
  EXPECT_THAT(doc, EndsWith(kEnd + kAfter));
}

TEST(QualityDocs, ADocumentWithoutItsMarkersIsRefusedBeforeTheBenchmarkRuns) {
  ScratchDir dir;
  const std::string text = kBefore + "no markers here\n" + kAfter;
  testing::write_text(dir / "doc.md", text);
  const auto r = run_script(dir, "--quick");
  EXPECT_EQ(r.exit_code, 65);
  EXPECT_THAT(r.err, HasSubstr((dir / "doc.md").string() + ": needs exactly one line starting '<!-- posefair bench quality: begin'"));
  EXPECT_EQ(testing::slurp(dir / "doc.md"), text);
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "the benchmark ran";

  // Markers in the wrong order are refused too.
  testing::write_text(dir / "doc.md", kBefore + kEnd + kBegin + kAfter);
  EXPECT_EQ(run_script(dir, "--quick").exit_code, 65);
}

TEST(QualityDocs, AFailedBenchmarkLeavesTheDocumentAsItWas) {
  ScratchDir dir;
  const std::string text = kBefore + kBegin + "the last good tables\n" + kEnd + kAfter;
  testing::write_text(dir / "doc.md", text);
  const auto r = run_script(dir, "--quick --set no-such-set");
  EXPECT_EQ(r.exit_code, 64) << "the benchmark's own exit status";
  EXPECT_THAT(r.err, HasSubstr("no data set or kind 'no-such-set'"));
  EXPECT_THAT(r.err, HasSubstr("doc.md is unchanged"));
  EXPECT_EQ(testing::slurp(dir / "doc.md"), text);
}

}  // namespace
}  // namespace posefair
