// The never-worse gate through the command line (issue 43 item 2, issue 39 item 5): clean
// simulated robots written, a truly worse calibration refused with its margin stated, the
// time-block verdict the same for 2, 4 and 8 blocks. The data are fitcal's simulator's; the
// judgements compare against what the simulator was told (the truth, a wheel scaled on purpose),
// not against fitcal's own earlier output.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::Has;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;
using testing::WriteFileBytes;

// A clean simulated omni robot (no effect beyond the model; the true robot a quarter of the way to
// its bounds), two repetitions: repetition 2 is held out, so each flower family (R, G, B) holds 12
// runs of 12 different paths and no path repeats. Before, differences inside the noise on one
// family refused such robots (issue 43: "'ceres' is worse than the nominal on the held-out 'G'
// runs (12)"); the calibration recovers the truth, so it must be written.
TEST(GateCli, ACleanRobotIsWritten) {
  TempDir dir;
  const std::string data = dir.Path("omni"), out = dir.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(dir, "simulate --model omni --repetitions 2 --seed 3 --out " + data).exit_code,
            0);
  const auto r = RunFitcal(dir, "fit --logs " + data + " --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_TRUE(Has(r.out, "drift 0.5 m [%]")) << r.out;  // the short-range row (issue 42 item 8)
}

// The diff drive's true robot is the nominal; the calibration exported is the nominal with its
// right wheel 2 % larger (0.04284 m against 0.042 m): a truly worse calibration. export replays it
// on every run (the calibration was made on another data set) and refuses it (exit 5), nothing
// written.
TEST(GateCli, AWheelScaledByTwoPercentIsRefused) {
  TempDir dir;
  const std::string data = dir.Path("diff"), fitted = dir.Path("fitted.yaml");
  const std::string other = dir.Path("other");
  ASSERT_EQ(RunFitcal(dir, "simulate --model diff_drive --repetitions 2 --seed 5 --out " + other)
                .exit_code,
            0);
  ASSERT_EQ(RunFitcal(dir, "fit --logs " + other + " --out " + fitted).exit_code, 0);
  const std::string robot = other + "/robot.yaml";
  ASSERT_EQ(RunFitcal(dir, "simulate --model diff_drive --robot " + robot + " --truth " + robot +
                               " --repetitions 2 --seed 6 --out " + data)
                .exit_code,
            0);
  // The fitted file with the nominal's radii, the right one 2 % larger, and the nominal's track.
  std::string yaml = ReadFileBytes(fitted);
  yaml = std::regex_replace(yaml, std::regex("name: right, radius_m: [0-9.e-]+"),
                            "name: right, radius_m: 0.04284");
  yaml = std::regex_replace(yaml, std::regex("name: left, radius_m: [0-9.e-]+"),
                            "name: left, radius_m: 0.042");
  yaml = std::regex_replace(yaml, std::regex("wheel_separation_m: [0-9.e-]+"),
                            "wheel_separation_m: 0.2");
  const std::string worse = dir.Path("worse.yaml"), out = dir.Path("ros2.yaml");
  WriteFileBytes(worse, yaml);
  const auto r = RunFitcal(dir, "export ros2-control --calibration " + worse +
                                    " --controller diff_drive_controller --joints r,l --logs " +
                                    data + " --out " + out);
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_TRUE(Has(r.err, "worse than the nominal")) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// One long run (the diff drive's runs joined into one data set of one run is not needed: its
// first run alone), fitted on its track with nothing held out: judged on time blocks, and the
// verdict and the judgement's line are the same for --time-blocks 2, 4 and 8 (issue 39: 4
// refused, 2 and 8 wrote).
TEST(GateCli, TheTimeBlockVerdictDoesNotFlipWithTheCount) {
  TempDir dir;
  const std::string data = dir.Path("diff");
  ASSERT_EQ(RunFitcal(dir, "simulate --model diff_drive --repetitions 3 --seed 4 --out " + data)
                .exit_code,
            0);
  std::ifstream in(data + "/dataset.yaml");
  std::string robot_line, runs_line, first;
  std::getline(in, robot_line);
  std::getline(in, runs_line);
  std::getline(in, first);
  WriteFileBytes(data + "/dataset.yaml", robot_line + "\n" + runs_line + "\n" + first + "\n");
  std::string judged;
  int exit_code = -1;
  for (const char* count : {"2", "4", "8"}) {
    const auto r =
        RunFitcal(dir, "fit --logs " + data + " --no-output --time-blocks " + std::string(count));
    const std::size_t at = r.out.find("judged on held-out time blocks of the training runs");
    ASSERT_NE(at, std::string::npos) << r.out << r.err;
    const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
    if (exit_code < 0) {
      exit_code = r.exit_code;
      judged = line;
    }
    EXPECT_EQ(r.exit_code, exit_code) << count << "\n" << r.out << r.err;
    EXPECT_EQ(line, judged) << count;
    EXPECT_TRUE(Has(line, "2, 4, 8 blocks")) << line;
    EXPECT_TRUE(Has(line, "of 3 counts")) << line;
  }
  EXPECT_EQ(exit_code, 0);  // the simulated run calibrates
  // A count beside 2, 4 and 8 joins them: the judgement pools four counts, 6 among them.
  const auto six = RunFitcal(dir, "fit --logs " + data + " --no-output --time-blocks 6");
  EXPECT_TRUE(Has(six.out, "two folds each of 2, 4, 6, 8 blocks")) << six.out;
  EXPECT_TRUE(Has(six.out, "of 4 counts")) << six.out;
}

// A real session of two runs the time blocks refuse (OptiOdom's diff drive, square 231220200048:
// the fits beat the nominal for 1 of the 3 block counts): the judgement's line says that they do
// not beat it, not what a written calibration would be fitted on, and nothing is written.
TEST(GateCli, RefusedTimeBlocksDoNotDescribeACalibrationWritten) {
  const std::string session = FITCAL_SHARED_DIR + "/data/optiodom/diff/square/231220200048";
  if (!fs::is_directory(session)) GTEST_SKIP() << "no " << session;
  TempDir dir;
  const std::string data = dir.Path("data"), out = dir.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(dir, "import optiodom " + session + " --out " + data).exit_code, 0);
  const auto r = RunFitcal(dir, "fit --logs " + data + " --out " + out);
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_TRUE(Has(r.out, "judged on held-out time blocks")) << r.out;
  EXPECT_TRUE(Has(r.out, "they do not beat the nominal")) << r.out;
  EXPECT_FALSE(Has(r.out, "the calibration written is fitted on all of them")) << r.out;
  EXPECT_FALSE(fs::exists(out));
}

// A real 12-run session (OptiOdom's omni3, circular 221220201701) drives four paths, three runs
// each: repetitions 1-5 train on the first two and leave directions undetermined, and the fit
// loses to the nominal on the held-out paths. The refusal says what to try; --train-reps 1-99
// writes (its calibration beats the nominal on the robot's other sessions: stop 65's sweep).
TEST(GateCli, ARefusedSplitByRepetitionSaysWhatToTry) {
  const std::string session = FITCAL_SHARED_DIR + "/data/optiodom/omni3/circular/221220201701";
  if (!fs::is_directory(session)) GTEST_SKIP() << "no " << session;
  TempDir dir;
  const std::string data = dir.Path("data"), out = dir.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(dir, "import optiodom " + session + " --out " + data).exit_code, 0);
  const auto refused = RunFitcal(dir, "fit --logs " + data + " --out " + out);
  EXPECT_EQ(refused.exit_code, 5) << refused.out << refused.err;
  EXPECT_TRUE(Has(refused.err, "(repetitions 1-5) leave directions undetermined")) << refused.err;
  EXPECT_TRUE(Has(refused.err, "--train-reps 1-99 fits every run")) << refused.err;
  EXPECT_FALSE(fs::exists(out));
  const auto every_run = RunFitcal(dir, "fit --logs " + data + " --train-reps 1-99 --out " + out);
  EXPECT_EQ(every_run.exit_code, 0) << every_run.out << every_run.err;
  EXPECT_FALSE(Has(every_run.err, "leave directions undetermined")) << every_run.err;
  EXPECT_TRUE(fs::exists(out));
}

// A tie the robot does not obey (wheels of 30 and 90 mm tied to one radius): the tied fit loses to
// the nominal on its own training runs (CF 0.98 -> 1.78), so the refusal names the tie,
// not the split, and a track fit is not told to fit the track (stop 72's D-F7).
TEST(GateCli, ATieTheRobotDoesNotObeyIsNamedAsTheCause) {
  TempDir dir;
  const std::string robot = dir.Path("robot.yaml"), data = dir.Path("sim");
  WriteFileBytes(robot,
                 "model: diff_drive\nname: unequal\nwheels:\n"
                 "  - {name: port, side: left, radius_m: 0.03}\n"
                 "  - {name: starboard, side: right, radius_m: 0.09}\n"
                 "wheel_separation_m: 0.5\nbounds:\n  radius_m: [0.02, 0.1]\n"
                 "  wheel_separation_m: [0.4, 0.6]\n");
  ASSERT_EQ(RunFitcal(dir, "simulate --robot " + robot + " --out " + data + " --repetitions 10")
                .exit_code,
            0);
  const auto r = RunFitcal(dir, "fit --logs " + data + " --tie r_port,r_starboard --out " +
                                    dir.Path("cal.yaml"));
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_TRUE(Has(r.err, "no calibration beats the nominal even on the training runs")) << r.err;
  EXPECT_FALSE(Has(r.err, "leave directions undetermined")) << r.err;
  ASSERT_TRUE(Has(r.out, "residuals: track")) << r.out;
  EXPECT_FALSE(Has(r.out, "(--residuals track)")) << r.out;
  EXPECT_FALSE(fs::exists(dir.Path("cal.yaml")));
}

}  // namespace
}  // namespace fitcal
