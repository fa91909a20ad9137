// docs/pages.md's table of sizes and figures, re-measured: each OptiOdom robot imported (circular
// and square sessions), fitted and reported as the doc says, its free session reported with the
// same calibration, and every row compared with the doc (issue 42: rows stale after a change to
// the fit went unnoticed). A change that moves a figure fails here until the doc is re-measured.
// Skipped without ../shared/data/optiodom.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;

const std::string kOptiOdom = FITCAL_SHARED_DIR + "/data/optiodom";

// The cells of the row of docs/pages.md's table whose first cell is `name`; empty when none.
std::vector<std::string> DocRow(const std::string& name) {
  std::istringstream lines(ReadFileBytes(FITCAL_SOURCE_DIR + "/docs/pages.md"));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("| " + name + " |", 0) != 0) continue;
    std::vector<std::string> cells;
    std::istringstream row(line.substr(1));
    std::string cell;
    while (std::getline(row, cell, '|')) {
      const std::size_t first = cell.find_first_not_of(' ');
      cells.push_back(first == std::string::npos
                          ? ""
                          : cell.substr(first, cell.find_last_not_of(' ') - first + 1));
    }
    return cells;
  }
  return {};
}

std::string Format(const char* format, double a, double b) {
  char text[64];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

// A report directory as the table shows it: data set, size, verdict, held-out runs (worse), ATE
// RMSE in mm, CF, from the report's own metrics.json.
void ExpectRowMatches(const std::string& name, const std::string& report) {
  SCOPED_TRACE(name);
  const std::vector<std::string> doc = DocRow(name);
  ASSERT_EQ(doc.size(), 6u) << "no row '" << name << "' in docs/pages.md";
  const YAML::Node m = YAML::LoadFile(report + "/metrics.json");
  // The page's size moves by a few kB with every change to its template; the column says how big
  // the page is (all under 2 MB), so it holds within 10 %.
  const double size_mb = static_cast<double>(fs::file_size(report + "/index.html")) / 1e6;
  EXPECT_NEAR(std::stod(doc[1]), size_mb, 0.1 * size_mb) << doc[1];
  EXPECT_EQ(doc[2], m["verdict"]["level"].as<std::string>());
  EXPECT_EQ(doc[3], std::to_string(m["held_out_runs"].as<int>()) + " (" +
                        std::to_string(m["held_out_runs_worse"].as<int>()) + ")");
  EXPECT_EQ(doc[4], Format("%.1f -> %.1f mm", 1e3 * m["ate_rmse_m"]["before"].as<double>(),
                           1e3 * m["ate_rmse_m"]["after"].as<double>()));
  EXPECT_EQ(doc[5],
            Format("%.4f -> %.4f", m["cf"]["before"].as<double>(), m["cf"]["after"].as<double>()));
}

// The doc's commands for one robot: import its circular and square sessions, fit (held out: the
// repetitions it did not train on), report; then its free session with the same calibration.
void MeasureRobot(const std::string& robot, const std::string& free_session) {
  const std::string sessions = kOptiOdom + "/" + robot;
  if (!fs::is_directory(sessions)) GTEST_SKIP() << "no " << sessions;
  TempDir dir;
  const std::string data = dir.Path("D"), cal = dir.Path("cal.yaml");
  const auto import = RunFitcal(
      dir, "import optiodom " + sessions + "/circular/* " + sessions + "/square/* --out " + data);
  ASSERT_EQ(import.exit_code, 0) << import.err;
  const auto fit = RunFitcal(dir, "fit --logs " + data + " --out " + cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const auto report =
      RunFitcal(dir, "report --logs " + data + " --calibration " + cal + " --out " + dir.Path("r"));
  ASSERT_EQ(report.exit_code, 0) << report.err;
  ExpectRowMatches("OptiOdom " + robot, dir.Path("r"));
  if (free_session.empty()) return;
  const auto free_import = RunFitcal(
      dir, "import optiodom " + sessions + "/" + free_session + "/* --out " + dir.Path("F"));
  ASSERT_EQ(free_import.exit_code, 0) << free_import.err;
  const auto free_report = RunFitcal(
      dir, "report --logs " + dir.Path("F") + " --calibration " + cal + " --out " + dir.Path("f"));
  ASSERT_EQ(free_report.exit_code, 0) << free_report.err;
  ExpectRowMatches(robot + "/" + free_session, dir.Path("f"));
}

TEST(PagesFigures, Diff) { MeasureRobot("diff", "free"); }
TEST(PagesFigures, Tricycle) { MeasureRobot("tricyc", "free"); }
TEST(PagesFigures, Omni3) { MeasureRobot("omni3", "joystick"); }
TEST(PagesFigures, Omni4) { MeasureRobot("omni4", ""); }

}  // namespace
}  // namespace fitcal
