// README.md's excerpts of fitcal's output, against what fitcal prints today (issue 42: the run.sh
// excerpt still showed "+0.54%" where the tool printed "+1.626 deg"). An excerpt is a fenced block
// without a language that starts with fitcal's banner; the command that printed it is the one its
// banner names: `fit` on the shipped flower (tools/run.sh), and on the OptiOdom diff drive of the
// worked example (skipped without ../shared). Every line of an excerpt must be a line of the
// output, but for a line "..." (lines left out), a line ending in "..." (a prefix of one) and the
// solver's wall time, which no two runs share.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "fitcal/version.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::ReadFileBytes;
using testing::TempDir;

const std::string kFitcal = FITCAL_BINARY_DIR + "/tools/fitcal";

std::vector<std::string> LinesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The README's output block whose banner (first line) starts with `banner`; empty when none.
std::vector<std::string> Excerpt(const std::string& banner) {
  const std::vector<std::string> lines = LinesOf(ReadFileBytes(FITCAL_SOURCE_DIR + "/README.md"));
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
    if (lines[i] != "```" || lines[i + 1].rfind(banner, 0) != 0) continue;
    std::vector<std::string> block;
    for (std::size_t k = i + 1; k < lines.size() && lines[k] != "```"; ++k) {
      block.push_back(lines[k]);
    }
    return block;
  }
  return {};
}

// The solver's wall time ("..., 0.176 s" and whatever follows it) as "<t> s", and no trailing
// blanks (a table's padding, which an editor strips from the README).
std::string WithoutWallTime(const std::string& line) {
  const std::string trimmed = line.substr(0, line.find_last_not_of(' ') + 1);
  return std::regex_replace(trimmed, std::regex(", [0-9.]+ s( .*)?$"), ", <t> s");
}

void ExpectExcerptOf(const std::vector<std::string>& excerpt, const std::string& output) {
  ASSERT_FALSE(excerpt.empty()) << "no such excerpt in README.md";
  std::vector<std::string> printed;
  for (const std::string& line : LinesOf(output)) printed.push_back(WithoutWallTime(line));
  for (const std::string& line : excerpt) {
    const std::size_t dots = line.rfind("...");
    if (line.find_first_not_of(' ') == dots) continue;  // "  ...": lines left out
    const bool is_prefix = dots != std::string::npos && dots + 3 == line.size();
    const std::string want = is_prefix ? line.substr(0, dots) : WithoutWallTime(line);
    bool found = false;
    for (const std::string& p : printed)
      found = found || (is_prefix ? p.rfind(want, 0) == 0 : p == want);
    EXPECT_TRUE(found) << "README.md shows a line fitcal does not print:\n"
                       << line << "\nfitcal printed:\n"
                       << output;
  }
}

// `text` with every `from` replaced by `to`.
std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// What `command`, run in `directory`, prints on stdout.
std::string Stdout(const std::string& directory, const std::string& command, const TempDir& dir) {
  const std::string out = dir.Path("stdout.txt");
  const int status = std::system(("cd " + directory + " && " + command + " > " + out).c_str());
  EXPECT_EQ(status, 0) << command;
  return ReadFileBytes(out);
}

TEST(ReadmeExcerpts, RunShOnTheFlower) {
  TempDir dir;
  // tools/run.sh's command, from the repository root as it runs it.
  const std::string output = ReplaceAll(
      Stdout(FITCAL_SOURCE_DIR,
             kFitcal + " --logs data/flower --method ceres --out " + dir.Path("calibrated.yaml"),
             dir),
      dir.Path("calibrated.yaml"), "build/calibrated.yaml");  // where run.sh writes it
  ExpectExcerptOf(Excerpt(std::string("fitcal ") + kVersion + "  omni3 robot 'apr02'"), output);
}

TEST(ReadmeExcerpts, WorkedExampleOnTheDiffDrive) {
  const std::string diff = FITCAL_SHARED_DIR + "/data/optiodom/diff";
  if (!fs::is_directory(diff)) GTEST_SKIP() << "no " << diff;
  TempDir dir;
  const std::string data = dir.Path("od_diff");
  Stdout(".",
         kFitcal + " import optiodom " + diff + "/circular/* " + diff + "/square/* --out " + data,
         dir);
  std::string output =
      Stdout(".", kFitcal + " fit --logs " + data + " --out " + dir.Path("diff.yaml"), dir);
  // The README's data set is /tmp/od_diff, this one is the test's own directory.
  output = ReplaceAll(ReplaceAll(output, dir.Path("diff.yaml"), "diff.yaml"), data, "/tmp/od_diff");
  ExpectExcerptOf(Excerpt(std::string("fitcal ") + kVersion + "  diff_drive robot"), output);
  // The report on the free run (issue 42: it printed "validation: 1 runs").
  const std::string free = dir.Path("od_diff_free");
  Stdout(".", kFitcal + " import optiodom " + diff + "/free/* --out " + free, dir);
  std::string report = Stdout(".",
                              kFitcal + " report --logs " + free + " --calibration " +
                                  dir.Path("diff.yaml") + " --out " +
                                  dir.Path("diff_free_report") + " --tum",
                              dir);
  report = ReplaceAll(ReplaceAll(report, dir.Path("diff_free_report"), "diff_free_report"), data,
                      "/tmp/od_diff");
  ExpectExcerptOf(Excerpt("validation: 1 run ("), report);
}

// Issue 42: a newcomer met "CF" in the first example with its meaning further down, and found no
// word on where the OptiOdom recordings come from. The first "CF" of the README is its definition,
// and the worked example names the upstream repository.
TEST(ReadmeExcerpts, DefinesCfWhereFirstUsedAndNamesTheDataSource) {
  const std::string readme = ReadFileBytes(FITCAL_SOURCE_DIR + "/README.md");
  std::smatch first;
  ASSERT_TRUE(std::regex_search(readme, first, std::regex("\\bCF\\b")));
  std::smatch defined;  // "**CF** (Palacin Eq. 14) is ...", wrapped anywhere
  ASSERT_TRUE(std::regex_search(readme, defined, std::regex("\\*\\*CF\\*\\*\\s+\\(Palac")))
      << "no \"**CF** (Palacin Eq. 14) is ...\" in README.md";
  const std::size_t definition = defined.position(0);
  EXPECT_EQ(static_cast<std::size_t>(first.position(0)), definition + 2)
      << "README.md uses CF before it says what it is: "
      << readme.substr(first.position(0) > 80 ? first.position(0) - 80 : 0, 160);
  EXPECT_TRUE(std::regex_search(readme, std::regex("come from\\s+github\\.com/sousarbarb/optiodom")))
      << "README.md no longer names where the OptiOdom data come from";
}

}  // namespace
}  // namespace fitcal
