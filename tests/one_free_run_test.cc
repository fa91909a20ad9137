// One free-driving run calibrates every OptiOdom robot (issue 40 item 4; reads
// ../shared/data/optiodom, skipped without it). A plain `fitcal fit` of the one free run of the
// differential drive, the tricycle and the three-wheel omni (its joystick run turns the body and
// strafes) writes a calibration judged on the run's held-out time blocks, with a sigma for every
// parameter. The omni3 calibration is then replayed on the robot's circles and squares (runs it
// was not fitted on) by this file's own odometry, straight from the OptiOdom run files with the
// authors' kinematics (the data's README: wheel_disp_i = cos(phi_i) dx + sin(phi_i) dy - L_i
// dtheta, phi_i = delta_i - 90 deg), sharing no code with fitcal's import or replay: it must end
// nearer the ground truth than the nominal does. Measured: mean CF (Eq. 14) over the 67 runs
// 0.2709 -> 0.1350; before issue 40 the run was refused (exit 5). The nominal's 0.2709 agrees
// with fitcal's own replay of the same runs (docs/everyday_driving.md: 0.2707).

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_files.h"

namespace fitcal {
namespace one_free_run_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

namespace fs = std::filesystem;
using testing::RunFitcal;
using testing::TempDir;

const std::string kOptiOdom = FITCAL_SHARED_DIR + "/data/optiodom";

// Imports `runs` (shell glob) and fits them with fit's defaults; expects a written calibration
// with a finite, positive sigma for every parameter, and returns its YAML.
YAML::Node FitOneFreeRun(const TempDir& dir, const std::string& name, const std::string& runs) {
  const std::string data = dir.Path(name), cal = dir.Path(name + ".yaml");
  const auto import = RunFitcal(dir, "import optiodom " + runs + " --out " + data);
  EXPECT_EQ(import.exit_code, 0) << import.err;
  const auto fit = RunFitcal(dir, "fit --logs " + data + " --out " + cal);
  EXPECT_EQ(fit.exit_code, 0) << fit.out << fit.err;
  EXPECT_NE(fit.out.find("judged on held-out time blocks"), std::string::npos) << fit.out;
  if (!fs::exists(cal)) return YAML::Node();
  const YAML::Node yaml = YAML::LoadFile(cal);
  const YAML::Node sigma = yaml["calibration"]["sigma"];
  EXPECT_TRUE(sigma.IsMap()) << name;
  for (const auto& entry : sigma) {
    const double s = entry.second.as<double>();
    EXPECT_TRUE(std::isfinite(s) && s > 0.0) << name << " " << entry.first.as<std::string>();
  }
  return yaml;
}

// The authors' omni3: per wheel its distance L_i (m), radius r_i (m) and angle delta_i (rad).
struct Omni3 {
  std::array<double, 3> distance_m{}, radius_m{}, delta_rad{};
};

Omni3 Omni3Of(const YAML::Node& robot) {
  Omni3 o;
  for (int i = 0; i < 3; ++i) {
    const YAML::Node w = robot["wheels"][i];
    o.distance_m[i] = w["distance_m"].as<double>();
    o.radius_m[i] = w["radius_m"].as<double>();
    o.delta_rad[i] = w["angle_deg"].as<double>() * M_PI / 180.0;
  }
  return o;
}

// Final-pose CF (Palacin Eq. 14) of one OptiOdom run file (time, x, y, theta of the ground
// truth in the start frame, then the three wheels' ticks per cycle; 12288 ticks per wheel turn)
// replayed with `robot`: each cycle's body motion solves the three wheel equations (Cramer's
// rule), integrated at the cycle's mid heading.
double FinalPoseCf(const std::string& path, const Omni3& robot) {
  constexpr double kTicksPerTurn = 12.0 * 1024.0;
  std::ifstream in(path);
  std::string line;
  double x = 0.0, y = 0.0, theta = 0.0;
  std::array<double, 4> last{};
  while (std::getline(in, line)) {
    std::array<double, 7> v{};
    std::stringstream row(line);
    std::string cell;
    for (double& value : v) {
      std::getline(row, cell, ',');
      value = std::stod(cell);
    }
    double a[3][3], b[3];
    for (int i = 0; i < 3; ++i) {
      const double phi = robot.delta_rad[i] - M_PI / 2.0;
      a[i][0] = std::cos(phi);
      a[i][1] = std::sin(phi);
      a[i][2] = -robot.distance_m[i];
      b[i] = 2.0 * M_PI * robot.radius_m[i] * v[4 + i] / kTicksPerTurn;
    }
    const auto det = [](const double m[3][3]) {
      return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
             m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    };
    const double d = det(a);
    double motion[3];
    for (int c = 0; c < 3; ++c) {
      double m[3][3];
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[i][j] = j == c ? b[i] : a[i][j];
      }
      motion[c] = det(m) / d;
    }
    const double mid = theta + 0.5 * motion[2];
    x += std::cos(mid) * motion[0] - std::sin(mid) * motion[1];
    y += std::sin(mid) * motion[0] + std::cos(mid) * motion[1];
    theta += motion[2];
    last = {v[1], v[2], v[3], 0.0};
  }
  const double heading = std::remainder(theta - last[2], 2.0 * M_PI);
  return std::sqrt((x - last[0]) * (x - last[0]) + (y - last[1]) * (y - last[1]) +
                   heading * heading);
}

TEST(OneFreeRun, TheDiffDrivesFreeRunCalibrates) {
  if (!fs::is_directory(kOptiOdom + "/diff/free")) GTEST_SKIP() << "no " << kOptiOdom;
  TempDir dir;
  FitOneFreeRun(dir, "diff", kOptiOdom + "/diff/free/*");
}

TEST(OneFreeRun, TheTricyclesFreeRunCalibrates) {
  if (!fs::is_directory(kOptiOdom + "/tricyc/free")) GTEST_SKIP() << "no " << kOptiOdom;
  TempDir dir;
  FitOneFreeRun(dir, "tricyc", kOptiOdom + "/tricyc/free/*");
}

TEST(OneFreeRun, TheOmni3JoystickRunCalibratesAndHoldsOnItsCirclesAndSquares) {
  const std::string omni3 = kOptiOdom + "/omni3";
  if (!fs::is_directory(omni3 + "/joystick")) GTEST_SKIP() << "no " << kOptiOdom;
  TempDir dir;
  const YAML::Node calibrated = FitOneFreeRun(dir, "omni3", omni3 + "/joystick/*");
  ASSERT_TRUE(calibrated.IsMap());
  const YAML::Node nominal = YAML::LoadFile(dir.Path("omni3") + "/robot.yaml");
  double before = 0.0, after = 0.0;
  int runs = 0;
  for (const std::string kind : {"circular", "square"}) {
    for (const auto& session : fs::directory_iterator(omni3 + "/" + kind)) {
      for (const auto& file : fs::directory_iterator(session.path())) {
        if (file.path().string().find("_run-") == std::string::npos) continue;
        before += FinalPoseCf(file.path().string(), Omni3Of(nominal));
        after += FinalPoseCf(file.path().string(), Omni3Of(calibrated));
        ++runs;
      }
    }
  }
  ASSERT_GT(runs, 0);
  std::printf("omni3 circles and squares (%d runs), mean CF: nominal %.4f, calibrated on the "
              "joystick run %.4f\n",
              runs, before / runs, after / runs);
  // Any calibration that transfers ends below the nominal on runs it was not fitted on; one that
  // does not (a fit of the run's second half from 36 s, which carries a slip of the body at
  // its start: 0.278 -> 0.599 per session) ends above it. Measured margin: half the nominal's CF.
  EXPECT_LT(after, before);
}

}  // namespace
}  // namespace fitcal
