// `generalise --tie/--hold` (validation/generalisation.h EvaluateSplit with a ParameterTying,
// cli/tying_flags.h): the reduced model is fitted beside the full one on every split.
//   - library: a differential drive whose true radii differ by 2.4 %; the full fit finds them
//     apart, the tied fits ("fit (tied)", "fit (track, tied)") give both radii one value (exactly
//     equal: p = A q copies it) and leave a held parameter at its nominal. A tie that were ignored
//     would give the full fit's unequal radii; one that leaked into the full fit, equal ones there.
//   - command: with --tie the table, the leave-one-session-out summary and the everyday-driving
//     tables carry the tied fits; without it nothing says "tied"; an unknown name is refused by the
//     same code as `fit` (one line, exit 2, nothing on stdout);
//   - `compare --tie/--hold` on data/flower: a "<method> (tied)" row after each method's, whose
//     M^-1 has the structure of equal distances and nominal angles.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fit/parameter_tying.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/test_files.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"
#include "validation/generalisation.h"

namespace fitcal {
namespace {

const CandidateScore* Find(const SplitScores& s, const std::string& name) {
  for (const CandidateScore& c : s.candidates)
    if (c.name == name) return &c;
  return nullptr;
}

std::size_t Position(const SplitScores& s, const std::string& name) {
  for (std::size_t i = 0; i < s.candidates.size(); ++i)
    if (s.candidates[i].name == name) return i;
  return s.candidates.size();
}

TEST(GeneraliseTying, TiedFitsShareOneValueBesideTheFullFits) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  const Robot& robot = model->robot();
  const int r_left = RequireParameterIndex(robot, "r_left");
  const int r_right = RequireParameterIndex(robot, "r_right");
  const int separation = RequireParameterIndex(robot, "wheel_separation");
  std::vector<double> truth = robot.nominal;
  truth[r_left] = 0.0415;
  truth[r_right] = 0.0425;
  truth[separation] = 0.204;
  sim::SimulationOptions sim_options;
  sim_options.gt_position_sigma_m = 0.001;
  sim_options.gt_heading_sigma_rad = 0.002;
  sim_options.seed = 5;
  std::vector<AlignedRun> runs;
  std::vector<RunLog> logs;
  for (const sim::ModelSimulatedRun& run :
       sim::SimulateRuns(*model, truth, sim::DiffDriveCalibrationTrajectories(2), sim_options)) {
    runs.push_back(AlignRun(run.log));
    logs.push_back(run.log);
  }
  std::vector<const GroundTruthTrack*> ground_truth;
  for (const RunLog& log : logs) ground_truth.push_back(&log.ground_truth);
  GeneralisationSplit split{"rep 1", "rep 2", {}, {}};
  for (std::size_t i = 0; i < runs.size(); ++i)
    (runs[i].repetition == 1 ? split.train : split.test).push_back(i);
  ParameterTying tying;
  tying.groups = {{"r_left", "r_right"}};
  tying.held = {"wheel_separation"};
  ModelFitOptions options;
  options.ceres.num_threads = 1;
  const SplitScores scores = EvaluateSplit(
      *model, runs, split, options, TrackCandidates{nullptr, nullptr, {}, &ground_truth}, tying);

  // The full fits see the radii apart: the truth's difference is 1e-3 m, twice the margin below;
  // these fits find -0.99e-3 and -1.00e-3 m (seed 5), far from it.
  for (const char* full : {"fit", "fit (track)"}) {
    const CandidateScore* c = Find(scores, full);
    ASSERT_NE(c, nullptr) << full;
    EXPECT_GT(std::abs(c->parameters[r_left] - c->parameters[r_right]), 5e-4) << full;
    EXPECT_NE(c->parameters[separation], robot.nominal[separation]) << full;
  }
  for (const char* tied : {kTiedFitName, kTiedTrackFitName}) {
    const CandidateScore* c = Find(scores, tied);
    ASSERT_NE(c, nullptr) << tied;
    EXPECT_TRUE(c->is_fit);
    EXPECT_EQ(c->parameters[r_left], c->parameters[r_right]) << tied;
    EXPECT_EQ(c->parameters[separation], robot.nominal[separation]) << tied;
    EXPECT_NE(c->parameters[r_left], robot.nominal[r_left]) << tied;  // fitted, not left
  }
  // Each tied fit is scored right after its full fit.
  EXPECT_LT(Position(scores, "fit"), Position(scores, kTiedFitName));
  EXPECT_LT(Position(scores, kTiedFitName), Position(scores, "fit (track)"));
  EXPECT_EQ(Position(scores, "fit (track)") + 1, Position(scores, kTiedTrackFitName));

  // No tying, no tied candidates.
  const SplitScores full_only = EvaluateSplit(*model, runs, split, options);
  EXPECT_EQ(Find(full_only, kTiedFitName), nullptr);
  EXPECT_EQ(Find(full_only, kTiedTrackFitName), nullptr);
}

TEST(GeneraliseTying, CommandPrintsTiedFitsAndRefusesUnknownNames) {
  testing::TempDir dir;
  const std::string data = dir.Path("diff");
  ASSERT_EQ(testing::RunFitcal(
                dir, "simulate --model diff_drive --repetitions 2 --out " + data + " --seed 3")
                .exit_code,
            0);
  const std::string generalise = "generalise --logs " + data + " --train-trajectories square-ccw";
  const auto tied =
      testing::RunFitcal(dir, generalise + " --tie r_left,r_right --hold wheel_separation");
  ASSERT_EQ(tied.exit_code, 0) << tied.err;
  EXPECT_NE(tied.out.find("tied (one value): r_left=r_right\nheld at nominal (--hold): "
                          "wheel_separation\n"),
            std::string::npos)
      << tied.out;
  EXPECT_NE(tied.out.find("| 'square-ccw' -> others | fit (tied) |"), std::string::npos)
      << tied.out;
  EXPECT_NE(tied.out.find("| others -> 'square-ccw' | fit (track, tied) |"), std::string::npos)
      << tied.out;
  EXPECT_NE(tied.out.find("'square-ccw' -> others: fit (tied) "), std::string::npos) << tied.out;
  EXPECT_NE(tied.out.find("| fit (tied) | 6 |"), std::string::npos) << tied.out;  // LOSO

  const auto plain = testing::RunFitcal(dir, generalise);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("tied"), std::string::npos) << plain.out;

  const auto wrong = testing::RunFitcal(dir, generalise + " --tie r_left,r_nope");
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_EQ(std::count(wrong.err.begin(), wrong.err.end(), '\n'), 1) << wrong.err;
  EXPECT_NE(wrong.err.find("'r_nope'"), std::string::npos) << wrong.err;
  EXPECT_EQ(wrong.out, "");
}

// The second entry of the first row of a compare row's M^-1 (Palacin Eq. 6), as printed (four
// decimals). With R_a = R_b = R_c and the angles at their nominal 300/60/180 deg it prints 0.0000
// (wheel b's share of the body's x velocity vanishes); the full fit on the flower prints 0.0013.
double FirstRowSecondEntry(const std::string& out, const std::string& row_start) {
  const std::size_t row = out.find(row_start);
  if (row == std::string::npos) return NAN;
  const std::size_t space = out.find(' ', out.find('[', row));
  return std::stod(out.substr(space + 1));
}

TEST(GeneraliseTying, CompareAddsATiedRowPerMethodThroughTheSameFlags) {
  testing::TempDir dir;
  const std::string compare = "compare --logs " + std::string(FITCAL_SOURCE_DIR) +
                              "/data/flower --methods ceres slsqp --strategies STE "
                              "--repetitions 1 --no-output --quiet";
  const auto tied =
      testing::RunFitcal(dir, compare + " --tie R_a,R_b,R_c --hold delta_a,delta_b,delta_c");
  ASSERT_EQ(tied.exit_code, 0) << tied.err;
  EXPECT_NE(tied.out.find("tied (one value): R_a=R_b=R_c\n"), std::string::npos) << tied.out;
  for (const char* method : {"ceres", "slsqp"}) {
    const std::string full = std::string("| STE | ") + method + " | 1 | [";
    const std::string reduced = std::string("| STE | ") + method + " (tied) | 1 | [";
    // Printed with four decimals: the full fit's 0.0013 is 13 units, the tied one's 0.
    EXPECT_GT(std::abs(FirstRowSecondEntry(tied.out, full)), 5e-4) << tied.out;
    EXPECT_EQ(FirstRowSecondEntry(tied.out, reduced), 0.0) << tied.out;
  }
  const auto plain = testing::RunFitcal(dir, compare);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("tied"), std::string::npos) << plain.out;

  const auto wrong = testing::RunFitcal(dir, compare + " --hold delta_x");
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_EQ(std::count(wrong.err.begin(), wrong.err.end(), '\n'), 1) << wrong.err;
  EXPECT_NE(wrong.err.find("'delta_x'"), std::string::npos) << wrong.err;
  EXPECT_EQ(wrong.out, "");
}

}  // namespace
}  // namespace fitcal
