// A rise inside the runs' scatter said aloud, through the command line on the real OptiOdom diff
// drive (issue 42 item 8; reads ../shared/data/optiodom, skipped without it). Trained on the
// circles alone, the fit beats the nominal on the held-out squares in CF (0.068 -> 0.041) and is
// written, but their drift per 1 m rises 0.740 -> 0.836 % (+13 %), inside the margin of the
// squares' own scatter between repetitions (docs/never_worse.md). Issue 43 forbids refusing on
// noise, so it is not refused; it must not pass unsaid either: fit's everyday-driving row and
// report's summary.md drift row carry the judgement, and one warning line names the runs, the
// measure, before -> after and the margin. The line's numbers are checked against the table row
// fit prints beside it and against the rule (a rise over 5 %, under the margin); export and
// diagnose, which judge by the same rule, say it too.

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "tests/test_files.h"

namespace fitcal {
namespace never_worse_realdata_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

namespace fs = std::filesystem;
using testing::Has;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;

const std::string kDiff = FITCAL_SHARED_DIR + "/data/optiodom/diff";

// The line of `text` holding `needle`; empty when none.
std::string LineWith(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  if (at == std::string::npos) return "";
  const std::size_t start = text.rfind('\n', at) + 1;
  return text.substr(start, text.find('\n', at) - start);
}

TEST(NeverWorseRealData, ACirclesOnlyFitSaysItsSquaresDriftMoreWithinTheScatter) {
  if (!fs::is_directory(kDiff + "/circular")) GTEST_SKIP() << "no " << kDiff;
  TempDir dir;
  const std::string data = dir.Path("od_diff"), cal = dir.Path("cal.yaml");
  const auto import = RunFitcal(dir, "import optiodom " + kDiff + "/circular/* " + kDiff +
                                         "/square/* --out " + data);
  ASSERT_EQ(import.exit_code, 0) << import.err;
  // Fixed weights: with weights from the data (chosen on these held-out squares since issue 40)
  // the squares drift less than with the nominal, and this test is about the warning.
  const auto fit = RunFitcal(dir, "fit --logs " + data +
                                      " --train-trajectories '^circular' --weights fixed --out " +
                                      cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.out << fit.err;  // written: not refused on noise
  ASSERT_TRUE(fs::exists(cal));

  // The row: "drift 1 m [%] (N windows)  0.740  0.836  +13.0%  worse, within the scatter: ...".
  const std::string row = LineWith(fit.out, "drift 1 m [%] (");
  std::smatch r;
  ASSERT_TRUE(std::regex_search(
      row, r,
      std::regex("windows\\) +([0-9.]+) +([0-9.]+) +\\+[0-9.]+%  worse, within the scatter: "
                 "margin ([0-9.]+)$")))
      << fit.out;
  const double before = std::stod(r[1]), after = std::stod(r[2]), margin = std::stod(r[3]);
  EXPECT_GT(after, 1.05 * before) << row;  // more than the 5 % that is said
  EXPECT_LE(after - before, margin) << row;  // and inside the margin: not refused

  // The warning names the runs (all squares), the measure, before -> after and the margin, the
  // same numbers as the row to the digits each prints.
  const std::string warning = LineWith(fit.out, "within the runs' scatter: drift 1 m [%]");
  std::smatch w;
  ASSERT_TRUE(std::regex_search(
      warning, w,
      std::regex("^warning: 'ceres' is worse than the nominal on the held-out runs \\(43, all "
                 "'square'\\), within the runs' scatter: drift 1 m \\[%\\] ([0-9.]+) -> "
                 "([0-9.]+) \\(\\+[0-9.]+ %\\), within the margin ([0-9.]+) ")))
      << fit.out;
  EXPECT_NEAR(std::stod(w[1]), before, 5e-4) << warning;
  EXPECT_NEAR(std::stod(w[2]), after, 5e-4) << warning;
  EXPECT_NEAR(std::stod(w[3]), margin, 5e-4 * margin + 1e-12) << warning;

  // report: the drift row of summary.md and the line under the verdict's key numbers.
  const auto report =
      RunFitcal(dir, "report --logs " + data + " --calibration " + cal + " --out " +
                         dir.Path("report"));
  ASSERT_EQ(report.exit_code, 0) << report.err;
  const std::string summary = ReadFileBytes(dir.Path("report/summary.md"));
  EXPECT_TRUE(std::regex_search(
      summary, std::regex("\\n\\| 1 \\| [0-9]+ \\| 0\\.7[0-9] \\| 0\\.8[0-9] \\(worse, within the "
                          "scatter: margin [0-9.]+\\) \\|")))
      << summary;
  EXPECT_TRUE(Has(summary, "- **worse:** 'the calibration' is worse than the nominal on the "
                           "held-out runs (43, all 'square'), within the runs' scatter: drift 1 m"))
      << summary;

  // export and diagnose say it by the same rule (validation/never_worse.h SayNeverWorse): the
  // exported parameters are the fit's (the same drift to the digit), on stdout and in the YAML's
  // comments; diagnose's own choice from the same split, on stdout.
  const std::string said_by_export =
      "warning: 'the exported parameters' is worse than the nominal on the held-out runs (43, all "
      "'square'), within the runs' scatter: drift 1 m [%] ";
  const auto exported =
      RunFitcal(dir, "export ros2-control --controller diff_drive_controller --calibration " + cal +
                         " --logs " + data + " --out " + dir.Path("controller.yaml"));
  ASSERT_EQ(exported.exit_code, 0) << exported.out << exported.err;
  EXPECT_NE(LineWith(exported.out, said_by_export).find(w[1].str() + " -> " + w[2].str()),
            std::string::npos)
      << exported.out;
  EXPECT_TRUE(Has(ReadFileBytes(dir.Path("controller.yaml")), "# " + said_by_export))
      << ReadFileBytes(dir.Path("controller.yaml"));
  const auto diagnosed = RunFitcal(dir, "diagnose --logs " + data +
                                            " --train-trajectories '^circular' --out " +
                                            dir.Path("diagnose"));
  ASSERT_EQ(diagnosed.exit_code, 0) << diagnosed.out << diagnosed.err;
  EXPECT_TRUE(std::regex_search(
      diagnosed.out,
      std::regex("\\nwarning: '[^']+' is worse than the nominal on the held-out runs \\(43, all "
                 "'square'\\), within the runs' scatter: drift 1 m \\[%\\] 0\\.7[0-9]+ -> "
                 "0\\.8[0-9]+ \\(\\+1[0-9]\\.[0-9] %\\)")))
      << diagnosed.out;
}

}  // namespace
}  // namespace fitcal
