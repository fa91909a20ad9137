// The final-pose kernel (odometry/omni3_final_pose_kernel.h) against the replay of Eq. 4 it
// replaces in the NLopt objective: the same final pose to rounding for every series tier, for
// run lengths that do not fill a block, and for the simulated flower runs at parameters spread
// over the Eq. 16 box.

#include "odometry/omni3_final_pose_kernel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "odometry/omni3_replay.h"
#include "tools/sim/omni3_simulator.h"

namespace fitcal::omni3 {
namespace {

using ParameterArray = std::array<double, kNumParameters>;

// Rates (rad/s) around a common spin `spin_rad_s` of the wheels, which turns the robot at roughly
// r/(3R) * 3 * spin: the spin sets how far the heading moves inside a block, hence the tier.
EncoderSamples SpinningLog(std::size_t n, double spin_rad_s, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> rate(-3.0, 3.0), dt(0.005, 0.015);
  EncoderSamples samples(3);
  samples.resize(n);
  for (auto&& s : samples) {
    s.dt_s = dt(rng);
    for (int i = 0; i < 3; ++i) s.value[i] = spin_rad_s + rate(rng);
  }
  return samples;
}

// |a - b| in position relative to the path length, and in heading.
void ExpectSamePose(const Pose2d& kernel, const Pose2d& replay, double path_m) {
  // Both sum the same terms in different orders: a few ulps per sample of the path.
  const double tol_m = 1e-13 * (1.0 + path_m);
  EXPECT_NEAR(kernel.x, replay.x, tol_m);
  EXPECT_NEAR(kernel.y, replay.y, tol_m);
  EXPECT_NEAR(kernel.theta, replay.theta, 1e-12 * (1.0 + std::abs(replay.theta)));
}

double PathLength(const Eigen::Matrix3d& m_inv, const EncoderSamples& samples) {
  double length = 0.0;
  for (const auto& s : samples) {
    const Eigen::Vector3d v = m_inv * Eigen::Vector3d(s.value[0], s.value[1], s.value[2]);
    length += std::hypot(v[0], v[1]) * s.dt_s;
  }
  return length;
}

TEST(FinalPoseKernel, EqualsTheReplayInEverySeriesTier) {
  const ParameterArray p = sim::PalacinTable5Parameters().ToArray();
  const Eigen::Matrix3d m_inv = InverseKinematicMatrix(p.data());
  const Pose2d start{0.4, -1.2, 2.9};
  // Spins from none (short series) to a robot turning ~3 turns/s (library sin/cos in most blocks).
  for (double spin : {0.0, 2.0, 5.0, 10.0, 40.0, 150.0}) {
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{63}, std::size_t{64},
                          std::size_t{65}, std::size_t{1000}}) {
      SCOPED_TRACE("spin " + std::to_string(spin) + " rad/s, " + std::to_string(n) + " samples");
      const EncoderSamples log = SpinningLog(n, spin, static_cast<unsigned>(n + 7));
      const Pose2d replay = ReplayWithMatrix(m_inv, log, 0, log.size(), start);
      const Pose2d kernel = FinalPoseKernel(log).FinalPose(m_inv, start);
      ExpectSamePose(kernel, replay, PathLength(m_inv, log));
    }
  }
}

TEST(FinalPoseKernel, EqualsTheReplayOnFlowerRunsOverTheParameterBox) {
  sim::Omni3SimulationOptions options;
  options.repetitions = 1;
  const std::vector<sim::SimulatedRun> runs = sim::SimulateOmni3(options);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> distance(0.170, 0.220), radius(0.138, 0.158),
      angle(-0.035, 0.035);
  for (int draw = 0; draw < 5; ++draw) {
    ParameterArray p = sim::PalacinTable5Parameters().ToArray();
    for (int i = 0; i < 3; ++i) {
      p[i] = distance(rng);  // Eq. 15 order: R_a..R_c, r_a..r_c, delta_a..delta_c
      p[3 + i] = radius(rng);
      p[6 + i] += angle(rng);
    }
    const Eigen::Matrix3d m_inv = InverseKinematicMatrix(p.data());
    for (const sim::SimulatedRun& run : runs) {
      const EncoderSamples& log = run.log.encoders.samples;
      const Pose2d start{0.0, 0.0, 0.3};
      ExpectSamePose(FinalPoseKernel(log).FinalPose(m_inv, start),
                     ReplayWithMatrix(m_inv, log, 0, log.size(), start), PathLength(m_inv, log));
    }
  }
}

TEST(FinalPoseKernel, SeesAWheelSwap) {
  // Not a symmetric function of the wheels: swapping two columns of the data moves the pose as
  // much as in the replay (guards against summing the wrong step with the wrong offset).
  const ParameterArray p = sim::PalacinTable5Parameters().ToArray();
  const Eigen::Matrix3d m_inv = InverseKinematicMatrix(p.data());
  EncoderSamples log = SpinningLog(500, 5.0, 11);
  EncoderSamples swapped = log;
  for (auto&& s : swapped) std::swap(s.value[0], s.value[1]);
  const Pose2d a = FinalPoseKernel(log).FinalPose(m_inv, Pose2d{});
  const Pose2d b = FinalPoseKernel(swapped).FinalPose(m_inv, Pose2d{});
  const Pose2d rb = ReplayWithMatrix(m_inv, swapped, 0, swapped.size(), Pose2d{});
  EXPECT_GT(std::hypot(a.x - b.x, a.y - b.y), 0.01);
  ExpectSamePose(b, rb, PathLength(m_inv, swapped));
}

}  // namespace
}  // namespace fitcal::omni3
