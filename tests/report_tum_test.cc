// `report --tum`: the TUM files of every judged run reproduce the ATE and the drift of
// metrics.json when recomputed a second way, independently of validation/relative_pose_error.cc
// and validation/trajectory_metrics.cc: the files read back by the ground-truth reader, poses as
// Eigen rigid transforms, every window found by walking the ground truth from its start.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "io/log_files.h"
#include "io/tum_file.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

using fitcal::testing::ReadFileBytes;
using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;

Eigen::Isometry2d Rigid(const Pose2d& p) {
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  T.linear() = Eigen::Rotation2Dd(p.theta).toRotationMatrix();
  T.translation() = Eigen::Vector2d(p.x, p.y);
  return T;
}

struct DriftSums {
  int windows = 0;
  double translation_percent = 0.0, rotation_deg_per_m = 0.0;
};

// KITTI's windows: from every sample to the first whose ground-truth path from it reaches L.
void AddWindows(const GroundTruthTrack& gt, const GroundTruthTrack& odo, double length_m,
                DriftSums* sums) {
  const std::size_t n = gt.world_T_robot.size();
  for (std::size_t i = 0; i < n; ++i) {
    double path = 0.0;
    std::size_t j = i;
    while (j + 1 < n && path < length_m) {
      path += std::hypot(gt.world_T_robot[j + 1].x - gt.world_T_robot[j].x,
                         gt.world_T_robot[j + 1].y - gt.world_T_robot[j].y);
      ++j;
    }
    if (path < length_m) return;
    const Eigen::Isometry2d truth =
        Rigid(gt.world_T_robot[i]).inverse() * Rigid(gt.world_T_robot[j]);
    const Eigen::Isometry2d est =
        Rigid(odo.world_T_robot[i]).inverse() * Rigid(odo.world_T_robot[j]);
    const Eigen::Isometry2d e = truth.inverse() * est;
    sums->translation_percent += 100.0 * e.translation().norm() / length_m;
    sums->rotation_deg_per_m +=
        std::abs(Eigen::Rotation2Dd(e.linear()).smallestAngle()) * 180.0 / M_PI / length_m;
    ++sums->windows;
  }
}

double AteRmse(const GroundTruthTrack& gt, const GroundTruthTrack& odo) {
  double sum = 0.0;
  for (std::size_t i = 0; i < gt.world_T_robot.size(); ++i) {
    sum += std::pow(gt.world_T_robot[i].x - odo.world_T_robot[i].x, 2) +
           std::pow(gt.world_T_robot[i].y - odo.world_T_robot[i].y, 2);
  }
  return std::sqrt(sum / static_cast<double>(gt.world_T_robot.size()));
}

void ExpectRelativelyNear(double a, double b, const std::string& what) {
  // metrics.json prints 10 significant digits.
  EXPECT_NEAR(a, b, 1e-8 * std::max(std::abs(b), 1e-12)) << what;
}

TEST(ReportTum, TumFilesReproduceAteAndDrift) {
  TempDir dir;
  const std::string data = std::string(FITCAL_SOURCE_DIR) + "/data/flower";
  // A calibration: the flower's robot with wheel a's distance at the simulated truth (Table 5).
  std::string robot = ReadFileBytes(data + "/robot.yaml");
  const std::string from = "{name: a, distance_m: 0.195";
  ASSERT_NE(robot.find(from), std::string::npos);
  robot.replace(robot.find(from), from.size(), "{name: a, distance_m: 0.2186");
  const std::string cal = dir.Write("cal.yaml", robot);
  const std::string out = dir.Path("rep");
  const auto r = RunFitcal(dir, "report --logs " + data + " --calibration " + cal +
                                    " --train-reps 1-9 --tum --worst-runs 0 --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node j = YAML::LoadFile(out + "/metrics.json");
  ASSERT_GT(j["runs"].size(), 0u);
  ASSERT_GT(j["drift"].size(), 0u);
  std::vector<DriftSums> before(j["drift"].size()), after(j["drift"].size());
  double ate_before = 0.0, ate_after = 0.0;
  for (const YAML::Node& run : j["runs"]) {
    const std::string stem = out + "/tum/" + io::FileNameOf(run["run"].as<std::string>());
    const GroundTruthTrack gt = io::ReadGroundTruth(stem + ".ground_truth.tum");
    const GroundTruthTrack nominal = io::ReadGroundTruth(stem + ".nominal.tum");
    const GroundTruthTrack calibrated = io::ReadGroundTruth(stem + ".calibrated.tum");
    ASSERT_EQ(gt.t_s, nominal.t_s);
    ASSERT_EQ(gt.t_s, calibrated.t_s);
    const double run_before = AteRmse(gt, nominal), run_after = AteRmse(gt, calibrated);
    ExpectRelativelyNear(run_before, run["ate_rmse_m"]["before"].as<double>(), "run ATE before");
    ExpectRelativelyNear(run_after, run["ate_rmse_m"]["after"].as<double>(), "run ATE after");
    ate_before += run_before / static_cast<double>(j["runs"].size());
    ate_after += run_after / static_cast<double>(j["runs"].size());
    for (std::size_t k = 0; k < j["drift"].size(); ++k) {
      const double length = j["drift"][k]["length_m"].as<double>();
      AddWindows(gt, nominal, length, &before[k]);
      AddWindows(gt, calibrated, length, &after[k]);
    }
  }
  ExpectRelativelyNear(ate_before, j["ate_rmse_m"]["before"].as<double>(), "ATE before");
  ExpectRelativelyNear(ate_after, j["ate_rmse_m"]["after"].as<double>(), "ATE after");
  EXPECT_LT(ate_after, ate_before);  // the calibration moved something
  for (std::size_t k = 0; k < j["drift"].size(); ++k) {
    const YAML::Node& d = j["drift"][k];
    EXPECT_EQ(before[k].windows, d["windows"].as<int>());
    const double n = before[k].windows;
    ExpectRelativelyNear(before[k].translation_percent / n,
                         d["translation_percent"]["before"].as<double>(), "translation before");
    ExpectRelativelyNear(after[k].translation_percent / n,
                         d["translation_percent"]["after"].as<double>(), "translation after");
    ExpectRelativelyNear(before[k].rotation_deg_per_m / n,
                         d["rotation_deg_per_m"]["before"].as<double>(), "rotation before");
    ExpectRelativelyNear(after[k].rotation_deg_per_m / n,
                         d["rotation_deg_per_m"]["after"].as<double>(), "rotation after");
  }
}

}  // namespace
}  // namespace fitcal
