// Identifiability (diagnosis/identifiability.h): the warning must fire for Palacin's strategy STA
// (straight runs R1, R5, R9 only) and stay silent for STE (all 36 flower trajectories).
//
// Why STA cannot work: straight runs command omega = 0, so the wheel rates w = M_nom (vx, vy, 0)
// always lie in the plane spanned by the first two columns of M_nom; the odometry only ever sees
// M^-1 applied to that plane. A change of the R_i alters the third column of M only, and (for
// the symmetric nominal robot, whose M^-1 has an equal-weight omega row) changes M^-1 only along
// the wheel-rate direction (1, 1, 1), i.e. outside that plane: all three R_i are unobservable.

#include "diagnosis/identifiability.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "fit/strategies.h"
#include "odometry/aligned_run.h"
#include "tools/sim/flower_candidates.h"
#include "tools/sim/omni3_simulator.h"

namespace fitcal {
namespace {

std::vector<AlignedRun> SimulatedRuns(const std::vector<std::string>& labels, int repetitions,
                                      std::uint64_t seed) {
  sim::Omni3SimulationOptions options;
  options.repetitions = repetitions;
  options.seed = seed;
  options.trajectories.clear();
  for (const sim::MotionCommand& c : sim::FlowerTrajectories()) {
    if (std::find(labels.begin(), labels.end(), c.label) != labels.end()) {
      options.trajectories.push_back(c);
    }
  }
  std::vector<AlignedRun> runs;
  for (const sim::SimulatedRun& run : sim::SimulateOmni3(options)) {
    runs.push_back(AlignRun(run.log));
  }
  return runs;
}

const std::vector<std::string>& Labels(const std::string& name) {
  for (const TrajectoryStrategy& s : PalacinStrategies()) {
    if (s.name == name) return s.labels;
  }
  throw std::runtime_error("no strategy " + name);
}

IdentifiabilityReport Analyse(const std::string& strategy) {
  // The Jacobian is evaluated at the true parameters (Table 5): where a good fit would end.
  const Omni3ParameterArray p = sim::PalacinTable5Parameters().ToArray();
  const Omni3ParameterArray nominal = sim::PalacinNominalParameters().ToArray();
  const auto runs = SimulatedRuns(Labels(strategy), 2, 7);
  return AnalyseIdentifiability(FinalPoseJacobian(p, runs), p, sim::FlowerCandidateMotions(),
                                nominal);
}

TEST(IdentifiabilityTest, StraightRunsOnlyCannotDetermineTheDistances) {
  const IdentifiabilityReport report = Analyse("STA");
  for (const std::string& line : IdentifiabilityLines(report)) std::printf("%s\n", line.c_str());
  EXPECT_FALSE(report.identifiable);
  EXPECT_TRUE(report.ill_conditioned);
  // Encoder quantisation leaves the null space only numerically non-empty; the three weakest
  // directions must be the R_i (see the comment at the top).
  ASSERT_GE(report.weak_directions.size(), 3u);
  const std::vector<std::string> expected = {"R_a", "R_b", "R_c"};
  EXPECT_EQ(report.unobservable_parameters, expected);
  // Any turning trajectory sees the lever arms: the advice must name a curve family, not the
  // straight runs.
  ASSERT_FALSE(report.fixing_kinds.empty());
  for (const std::string& kind : report.fixing_kinds) {
    EXPECT_NE(kind.find("curve"), std::string::npos) << kind;
  }
  const auto lines = IdentifiabilityLines(report);
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines[0].find("warning"), std::string::npos);
}

TEST(IdentifiabilityTest, WholeFlowerDeterminesAllNine) {
  const IdentifiabilityReport report = Analyse("STE");
  std::printf("STE condition number %.3g\n", report.condition_number);
  EXPECT_TRUE(report.identifiable);
  EXPECT_FALSE(report.rank_deficient);
  EXPECT_FALSE(report.ill_conditioned);
  EXPECT_TRUE(report.correlated_pairs.empty());
  EXPECT_TRUE(IdentifiabilityLines(report).empty());
}

TEST(IdentifiabilityTest, DescribesACommonScaleInWords) {
  // A synthetic Jacobian blind to exactly one direction: scaling every R_i and r_i together.
  // (Built from random rows projected orthogonal to that direction, in relative units.)
  const Omni3ParameterArray p = sim::PalacinNominalParameters().ToArray();
  Omni3Vector blind_rel;
  blind_rel << 1, 1, 1, 1, 1, 1, 0, 0, 0;
  blind_rel.normalize();
  Eigen::MatrixXd j_rel = Eigen::MatrixXd::Random(30, omni3::kNumParameters);
  j_rel -= (j_rel * blind_rel) * blind_rel.transpose();
  Omni3Vector inv_scale;
  for (int k = 0; k < omni3::kNumParameters; ++k) inv_scale[k] = k < 6 ? 1.0 / p[k] : 1.0;
  const IdentifiabilityReport report =
      AnalyseIdentifiability(j_rel * inv_scale.asDiagonal(), p, {}, p);
  EXPECT_TRUE(report.rank_deficient);
  ASSERT_EQ(report.weak_directions.size(), 1u);
  EXPECT_NE(report.weak_directions[0].description.find("a common scale of all r_i and R_i"),
            std::string::npos)
      << report.weak_directions[0].description;
  EXPECT_NEAR(std::abs(report.weak_directions[0].direction_rel.dot(blind_rel)), 1.0, 1e-9);
}

}  // namespace
}  // namespace fitcal
