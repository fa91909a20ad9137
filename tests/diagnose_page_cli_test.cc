// `diagnose` writes a page and metrics.json (no residual CSVs unless --csv), and its held-out CF
// is the one `report` prints for the same calibration on the same runs: the defect was two CFs for
// one calibration, unexplained (the gate's track replay against report's replay).

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "tests/test_files.h"

namespace fitcal {
namespace {

using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;

TEST(DiagnosePageCli, PageMetricsAndTheReportsCf) {
  TempDir dir;
  const std::string data = std::string(FITCAL_SOURCE_DIR) + "/data/undeclared_effect";
  const std::string diag = dir.Path("diag"), rep = dir.Path("rep");
  const auto d = RunFitcal(dir, "diagnose --logs " + data + " --out " + diag);
  ASSERT_EQ(d.exit_code, 0) << d.err;
  namespace fs = std::filesystem;
  for (const char* f : {"index.html", "metrics.json", "diagnose.md", "calibrated.yaml"}) {
    EXPECT_TRUE(fs::exists(diag + "/" + f)) << f;
  }
  EXPECT_FALSE(fs::exists(diag + "/residuals.csv"));  // only with --csv
  EXPECT_LT(fs::file_size(diag + "/index.html"), 5u << 20);
  const auto r = RunFitcal(dir, "report --logs " + data + " --calibration " + diag +
                                    "/calibrated.yaml --worst-runs 0 --out " + rep);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node jd = YAML::LoadFile(diag + "/metrics.json");
  const YAML::Node jr = YAML::LoadFile(rep + "/metrics.json");
  EXPECT_EQ(jd["kind"].as<std::string>(), "diagnose");
  EXPECT_EQ(jd["held_out_runs"].as<int>(), jr["held_out_runs"].as<int>());
  for (const char* key : {"cf", "ate_rmse_m"}) {
    for (const char* when : {"before", "after"}) {
      const double a = jd[key][when].as<double>(), b = jr[key][when].as<double>();
      // The same replay (validation/trajectory_metrics.h) on the same runs; omni3's own replay
      // in report equals the seam's to rounding.
      EXPECT_NEAR(a, b, 1e-7 * std::abs(b)) << key << " " << when;
    }
  }
}

}  // namespace
}  // namespace fitcal
