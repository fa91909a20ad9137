// A covariance an EKF can trust (issue 43 item 6), checked against the TRUE motion of the
// independent simulator (tests/independent_sim/: no fitcal code), as a user runs fitcal:
// `fit` on four runs, `export ros2-control --logs` (covariance from eight held-out runs), and
// then (the calibration moved to the true geometry, SetTrueGeometry), on twelve runs of another
// seed the export never saw, what diff_drive_controller computes
// from the written parameters (its odometry re-implemented here from the encoder ticks) against
// the simulator's true poses:
// - twist per message while the wheels turn (each encoder interval, 20 ms: the controller's
//   default publish rate of 50 Hz; at rest the twist is exactly 0 and right), against the true mean body twist over the interval in the frame at its middle: vx and
//   omega (vy: the controller publishes 0 and the simulated rigid body has no lateral slip, so
//   there is no error to cover);
// - pose after 1 m of path (the controller's constant pose covariance), from non-overlapping
//   windows: x, y, theta in the true frame at the window's start.
// At three slip levels (traction and wandering slip x1, x2, x3) every quantity's share of errors
// inside 1 and 2 sigma must lie in 60-76 % and 92-98 % (Gaussian: 68.3 %, 95.4 %), and the
// sigmas must grow with the slip (below).
//
// Sample sizes: ~90,000 messages per level (binomial sigma of a share 0.2 %), ~490 pose windows
// (2.1 % at 68 %, 0.9 % at 95 %): the bands are ~4 binomial sigmas of the pose share wide on
// either side; the twist's is dominated by whether the variance is right.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/independent_sim/everyday_drive_sim.h"
#include "tests/test_files.h"

namespace {

using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;
namespace sim = independent_sim;

struct Controller {  // diff_drive_controller's parameters as exported
  double r_right = 0.0, r_left = 0.0, separation = 0.0;
  std::array<double, 6> pose{}, twist{};
};

Controller ReadController(const std::string& path) {
  const YAML::Node p = YAML::LoadFile(path)["diff_drive_controller"]["ros__parameters"];
  Controller c;
  const double r = p["wheel_radius"].as<double>();
  c.r_right = r * p["right_wheel_radius_multiplier"].as<double>();
  c.r_left = r * p["left_wheel_radius_multiplier"].as<double>();
  c.separation = p["wheel_separation"].as<double>() * p["wheel_separation_multiplier"].as<double>();
  for (int i = 0; i < 6; ++i) {
    c.pose[i] = p["pose_covariance_diagonal"][i].as<double>();
    c.twist[i] = p["twist_covariance_diagonal"][i].as<double>();
  }
  return c;
}

// The fitted calibration moved to the simulator's geometry (its calibration block, which names
// the training runs, kept): the check then sees the covariance's model of the odometry's noise
// (slip, quantisation), not one seed's calibration error - a constant bias no variance covers
// message by message, and which the parameters' own sigmas cover
// (tests/independent_sigma_coverage_test.cc).
void SetTrueGeometry(const std::string& path) {
  YAML::Node cal = YAML::LoadFile(path);
  const sim::DiffDriveGeometry truth;
  cal["wheels"][0]["radius_m"] = truth.r_right_m;
  cal["wheels"][1]["radius_m"] = truth.r_left_m;
  cal["wheel_separation_m"] = truth.separation_m;
  YAML::Emitter out;
  out.SetDoublePrecision(12);
  out << cal;
  fitcal::testing::WriteFileBytes(path, std::string(out.c_str()) + "\n");
}

struct Share {
  int inside1 = 0, inside2 = 0, total = 0;
  void Add(double error, double variance) {
    const double sigma = std::sqrt(variance);
    inside1 += std::abs(error) <= sigma;
    inside2 += std::abs(error) <= 2.0 * sigma;
    ++total;
  }
  double One() const { return static_cast<double>(inside1) / total; }
  double Two() const { return static_cast<double>(inside2) / total; }
};

// Errors of the controller's odometry against the true motion: vx, omega per message; x, y,
// theta after each 1 m of odometry path.
std::array<Share, 5> Coverage(const Controller& c, const std::vector<sim::SimulatedRun>& runs,
                              int ticks_per_rev) {
  std::array<Share, 5> s;
  const double rad_per_tick = sim::kTwoPi / ticks_per_rev;
  for (const sim::SimulatedRun& run : runs) {
    double x = 0.0, y = 0.0, th = 0.0, path = 0.0;  // odometry since the window's start
    std::size_t window_start = 0;
    for (std::size_t k = 1; k < run.encoder_t_s.size(); ++k) {
      const double dt = run.encoder_t_s[k] - run.encoder_t_s[k - 1];
      const double right = c.r_right * rad_per_tick * (run.ticks_right[k] - run.ticks_right[k - 1]);
      const double left = c.r_left * rad_per_tick * (run.ticks_left[k] - run.ticks_left[k - 1]);
      const double ds = 0.5 * (right + left), dth = (right - left) / c.separation;
      // At rest no tick moves and the controller's twist is exactly right: nothing to cover.
      const bool moving = run.ticks_right[k] != run.ticks_right[k - 1] ||
                          run.ticks_left[k] != run.ticks_left[k - 1];
      const sim::Pose& a = run.true_pose_at_encoder[k - 1];
      const sim::Pose& b = run.true_pose_at_encoder[k];
      const double mid = 0.5 * (a.theta + b.theta);
      const double true_vx = (std::cos(mid) * (b.x - a.x) + std::sin(mid) * (b.y - a.y)) / dt;
      if (moving) {
        s[0].Add(ds / dt - true_vx, c.twist[0]);
        s[1].Add(dth / dt - (b.theta - a.theta) / dt, c.twist[5]);
      }
      x += ds * std::cos(th + 0.5 * dth);
      y += ds * std::sin(th + 0.5 * dth);
      th += dth;
      path += std::abs(ds);
      if (path < 1.0) continue;
      const sim::Pose& w = run.true_pose_at_encoder[window_start];
      const double tx = std::cos(w.theta) * (b.x - w.x) + std::sin(w.theta) * (b.y - w.y);
      const double ty = -std::sin(w.theta) * (b.x - w.x) + std::cos(w.theta) * (b.y - w.y);
      s[2].Add(x - tx, c.pose[0]);
      s[3].Add(y - ty, c.pose[1]);
      s[4].Add(th - (b.theta - w.theta), c.pose[5]);
      x = y = th = path = 0.0;
      window_start = k;
    }
  }
  return s;
}

std::vector<sim::SimulatedRun> Runs(const sim::ContactPhysics& physics, int count,
                                    std::uint64_t seed) {
  std::vector<sim::SimulatedRun> runs;
  for (int i = 0; i < count; ++i) {
    runs.push_back(sim::SimulateDiffDrive(sim::DiffDriveGeometry{}, physics, sim::Sensors{},
                                          sim::Drive{}, seed + i));
  }
  return runs;
}

// The along-track error after 1 m is heavier-tailed than a Gaussian (straights add almost none,
// turns and accelerations most): with its variance right, 80-82 % of the windows lie inside
// 1 sigma at every slip level (a Laplace distribution: 76 %), 96-97 % inside 2 sigma. The 1-sigma
// bound for it is therefore 0.86, not 0.76; its 2-sigma band stays 92-98 % (docs/ros2.md).
constexpr double kAlongTrackOneSigmaMax = 0.86;
// vx per message at the lowest slip is mostly the encoder quantisation's error (sums of
// differences of uniform errors, lighter-tailed than a Gaussian): 80.5 % inside 1 sigma, 94.9 %
// inside 2; at x2 and x3 72.8 % and 69.0 %. Bound 0.82 (a sigma at most ~1.3x wide).
constexpr double kVxOneSigmaMax = 0.82;

TEST(IndependentOdometryCovariance, CoversTheTrueMotionAtThreeSlipLevelsAndGrowsWithSlip) {
  const char* names[] = {"vx", "omega", "x after 1 m", "y after 1 m", "theta after 1 m"};
  std::vector<Controller> exported;
  for (double slip : {1.0, 2.0, 3.0}) {
    sim::ContactPhysics physics;
    physics.walk_sigma *= slip;
    physics.traction_slip_per_m_s2 *= slip;
    TempDir dir;
    // Repetitions 1-4 train, 5-12 estimate the covariance.
    sim::WriteDataSet(dir.path() / "data", Runs(physics, 12, 7000),
                      sim::DiffDriveGeometry{0.042, 0.042, 0.2}, sim::Sensors{});
    const std::string data = dir.Path("data"), cal = dir.Path("cal.yaml");
    const auto fit = RunFitcal(dir, "fit --logs " + data + " --train-reps 1-4 --out " + cal);
    ASSERT_EQ(fit.exit_code, 0) << fit.out << fit.err;
    SetTrueGeometry(cal);
    const auto exp = RunFitcal(dir, "export ros2-control --controller diff_drive_controller "
                                    "--calibration " + cal + " --logs " + data + " --out " +
                                        dir.Path("params.yaml"));
    ASSERT_EQ(exp.exit_code, 0) << exp.out << exp.err;
    std::printf("slip x%.0f: %s", slip, exp.out.c_str());
    exported.push_back(ReadController(dir.Path("params.yaml")));
    const std::array<Share, 5> s = Coverage(exported.back(), Runs(physics, 12, 9000),
                                            sim::Sensors{}.ticks_per_rev);
    for (int q = 0; q < 5; ++q) {
      std::printf("  slip x%.0f %-16s %5.1f %% / %5.1f %% of %d\n", slip, names[q],
                  100.0 * s[q].One(), 100.0 * s[q].Two(), s[q].total);
      EXPECT_GE(s[q].One(), 0.60) << names[q] << " slip x" << slip;
      const double one_sigma_max = q == 2 ? kAlongTrackOneSigmaMax : q == 0 ? kVxOneSigmaMax : 0.76;
      EXPECT_LE(s[q].One(), one_sigma_max) << names[q] << " slip x" << slip;
      EXPECT_GE(s[q].Two(), 0.92) << names[q] << " slip x" << slip;
      EXPECT_LE(s[q].Two(), 0.98) << names[q] << " slip x" << slip;
    }
  }
  // Sigmas grow with the slip: omega and every pose axis. vx's per-message variance is the
  // encoder quantisation's (0.9 mm/s) and the slip adds 0.1-0.3 mm/s, 1-10 % of the variance and
  // below what four runs under 1 mm motion capture resolve: it must not shrink.
  for (std::size_t level = 1; level < exported.size(); ++level) {
    EXPECT_GT(exported[level].twist[5], exported[level - 1].twist[5]) << "omega, level " << level;
    EXPECT_GE(exported[level].twist[0], exported[level - 1].twist[0]) << "vx, level " << level;
    for (int axis : {0, 1, 5}) {
      EXPECT_GT(exported[level].pose[axis], exported[level - 1].pose[axis]) << "pose " << axis;
    }
  }
}

}  // namespace
