// Issue 39 on everyday driving: what a user records most - free driving, a pose from a sensor on
// its mount, the maker's guesses far off - from the independent simulator
// (tests/independent_sim/steered_and_omni_sim.h: no fitcal code). A tricycle (true radius 0.0357
// m, wheelbase 0.18 m, steering offset 1 deg, gain 0.97) drives two ~40 m runs; its motion capture
// tracks a sensor at (1.5 m, -0.2 m, 5 deg) in the base frame (the simulator's centre pose moved
// onto the mount here, its noise then carried with it). The guesses: radius 9 % and wheelbase
// 17 % off, the steering gain 2.06x (2.0), the mount 0.3 m, 0.2 m and 5 deg off. The plain `fit`
// must write a calibration with every parameter and the mount within 3 of its written sigmas.
// Before the global start tried the fit of 0.5 m windows (fit/model_fit.cc, WithGlobalStart),
// seed 1 was refused with the radius on its bound and seed 2 exited 1 without a covariance: every
// start across the box stayed in a wrong minimum.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "models/model_registry.h"
#include "tests/independent_sim/steered_and_omni_sim.h"
#include "tests/test_files.h"
#include "tests/written_calibration_checks.h"

namespace free_drive_far_guess_cli_test {  // named, not anonymous: tests compile in batches

using fitcal::testing::ExpectEveryParameterWithin3WrittenSigmas;
using fitcal::testing::Has;
using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;
namespace sim = independent_sim;

constexpr double kMountX = 1.5, kMountY = -0.2, kMountYawDeg = 5.0;

std::string TricycleYaml(const sim::TricycleGeometry& g, double frame_x, double frame_y,
                         double frame_yaw_deg) {
  std::ostringstream out;
  out.precision(10);
  out << "model: tricycle\nname: t\ntraction_wheel: {radius_m: " << g.radius_m
      << "}\nwheelbase_m: " << g.wheelbase_m
      << "\nsteering_offset_deg: " << g.steering_offset_rad * 180.0 / M_PI
      << "\nsteering_gain: " << g.steering_gain
      << "\nbounds: {radius_m: [0.025, 0.045], wheelbase_m: [0.12, 0.25], "
         "steering_offset_deg: [-10.0, 10.0]}\n"
      << "encoder: {ticks_per_rev: 4096, cumulative: true}\n"
      << "ground_truth_frame: {x_m: " << frame_x << ", y_m: " << frame_y
      << ", yaw_deg: " << frame_yaw_deg << "}\n";
  return out.str();
}

// The sensor's pose: the centre's, moved onto the mount.
void OnTheMount(sim::MultiChannelRun* run) {
  const double yaw = kMountYawDeg * M_PI / 180.0;
  for (sim::Pose& p : run->mocap) {
    const double c = std::cos(p.theta), s = std::sin(p.theta);
    p = {p.x + c * kMountX - s * kMountY, p.y + s * kMountX + c * kMountY, p.theta + yaw};
  }
}

class FreeDriveFarGuess : public ::testing::TestWithParam<int> {};

TEST_P(FreeDriveFarGuess, TricycleAndItsSensorsMountFromTwoRuns) {
  const int seed = GetParam();
  const sim::TricycleGeometry truth;
  sim::Drive drive;
  drive.length_m = 40.0;
  std::vector<sim::MultiChannelRun> runs;
  for (int i = 0; i < 2; ++i) {
    runs.push_back(sim::SimulateTricycle(truth, sim::ContactPhysics{}, sim::SteeringActuator{},
                                         sim::Sensors{}, drive, 100 * seed + i));
    OnTheMount(&runs.back());
  }
  TempDir dir;
  const sim::TricycleGeometry guess{0.0325, 0.15, 0.0, 2.0};
  sim::WriteMultiChannelDataSet(dir.path() / "data", runs, TricycleYaml(guess, 1.2, 0.0, 0.0),
                                {"ticks_traction", "steering"});
  fitcal::testing::WriteFileBytes(dir.Path("truth.yaml"),
                                  TricycleYaml(truth, kMountX, kMountY, kMountYawDeg));
  const auto r =
      RunFitcal(dir, "fit --logs " + dir.Path("data") + " --out " + dir.Path("cal.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(Has(r.out, "the one from the windows' fit")) << r.out;
  // radius, wheelbase, offset, gain, the mount's three
  ASSERT_EQ(fitcal::ReadRobotModelFile(dir.Path("cal.yaml"))->robot().NumParameters(), 7);
  ExpectEveryParameterWithin3WrittenSigmas(dir.Path("cal.yaml"), dir.Path("truth.yaml"),
                                           "seed " + std::to_string(seed));
}

std::string Omni3Yaml(const sim::Omni3Geometry& g, double frame_x, double frame_y,
                      double frame_yaw_deg) {
  std::ostringstream out;
  out.precision(10);
  out << "model: omni3\nname: o\nwheels:\n";
  const char* names[] = {"a", "b", "c"};
  for (int i = 0; i < 3; ++i) {
    out << "  - {name: " << names[i] << ", distance_m: " << g.distance_m[i]
        << ", radius_m: " << g.radius_m[i] << ", angle_deg: " << g.angle_rad[i] * 180.0 / M_PI
        << "}\n";
  }
  out << "bounds: {distance_m: [0.140, 0.250], radius_m: [0.110, 0.190], "
         "angle_offset_deg: [-5.0, 5.0]}\n"
      << "encoder: {ticks_per_rev: 4096, cumulative: true}\n"
      << "ground_truth_frame: {x_m: " << frame_x << ", y_m: " << frame_y
      << ", yaw_deg: " << frame_yaw_deg << "}\n";
  return out.str();
}

// The same for a three-wheeled omni robot, whose sensor's x and y trade with its wheel distances
// (models/mounted_model.h). The mount guessed 0.3 m and 0.2 m off would need wheel distances
// below zero to take up the error (R_i' = R_i - x cos delta_i - y sin delta_i); held at the guess,
// the fit is poor. fitcal fits x and y with the distances then (calibrate/calibrate.cc), and the
// direction the two share is held at the nominal distances, 0.195 m against 0.192-0.200 m true:
// every parameter within 3 of its written sigmas of the truth.
TEST_P(FreeDriveFarGuess, Omni3AndItsSensorsMountFromTwoRuns) {
  const int seed = GetParam();
  const sim::Omni3Geometry truth;
  std::vector<sim::MultiChannelRun> runs;
  for (int i = 0; i < 2; ++i) {
    runs.push_back(sim::SimulateOmni3(truth, sim::ContactPhysics{}, sim::Sensors{}, sim::Drive{},
                                      100 * seed + i));
    OnTheMount(&runs.back());
  }
  TempDir dir;
  const sim::Omni3Geometry guess{{0.195, 0.195, 0.195}, {0.148, 0.148, 0.148},
                                 {M_PI / 3.0, M_PI, 5.0 * M_PI / 3.0}};
  sim::WriteMultiChannelDataSet(dir.path() / "data", runs, Omni3Yaml(guess, 1.2, 0.0, 0.0),
                                {"ticks_a", "ticks_b", "ticks_c"});
  fitcal::testing::WriteFileBytes(dir.Path("truth.yaml"),
                                  Omni3Yaml(truth, kMountX, kMountY, kMountYawDeg));
  const auto r =
      RunFitcal(dir, "fit --logs " + dir.Path("data") + " --out " + dir.Path("cal.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(Has(r.out, "not held at the guess (x 1.2 m, y 0 m)")) << r.out;
  // distances, radii, angles, the mount's three
  ASSERT_EQ(fitcal::ReadRobotModelFile(dir.Path("cal.yaml"))->robot().NumParameters(), 12);
  ExpectEveryParameterWithin3WrittenSigmas(dir.Path("cal.yaml"), dir.Path("truth.yaml"),
                                           "seed " + std::to_string(seed));
}

INSTANTIATE_TEST_SUITE_P(Seeds, FreeDriveFarGuess, ::testing::Values(1, 2));

}  // namespace free_drive_far_guess_cli_test
