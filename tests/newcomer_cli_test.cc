// A newcomer's first hour (issue 42), through the fitcal binary as a user types it: one overwrite
// rule for every command that writes (README, Outputs), the hints that turn common mistakes into
// the next step, and what every --help says (the exit statuses, no source headers, no parser
// artefacts). The real OptiOdom sessions are used where the mistake is theirs; without
// ../shared those tests are skipped.

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::Has;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;

const std::string kFlower = FITCAL_SOURCE_DIR + "/data/flower";
const std::string kDiff = FITCAL_SHARED_DIR + "/data/optiodom/diff";

// Rule 1: every command that writes replaces its own previous output when run again; rule 2: a
// file it did not write is refused with exit 2, nothing written, the message naming --force, and
// --force replaces it.
TEST(NewcomerCli, RunningEveryCommandAgainReplacesItsOwnOutput) {
  TempDir dir;
  const std::string data = dir.Path("data"), cal = dir.Path("cal.yaml");
  for (int pass = 0; pass < 2; ++pass) {
    SCOPED_TRACE("pass " + std::to_string(pass + 1));
    const auto simulate =
        RunFitcal(dir, "simulate --model diff_drive --repetitions 2 --seed 3 --out " + data);
    ASSERT_EQ(simulate.exit_code, 0) << simulate.err;
    const auto fit = RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + cal);
    ASSERT_EQ(fit.exit_code, 0) << fit.err;
    const auto report = RunFitcal(
        dir, "report --logs " + data + " --calibration " + cal + " --out " + dir.Path("rep"));
    EXPECT_EQ(report.exit_code, 0) << report.err;
    const auto diagnose = RunFitcal(dir, "diagnose --logs " + data + " --out " + dir.Path("diag"));
    EXPECT_TRUE(diagnose.exit_code == 0 || diagnose.exit_code == 5) << diagnose.err;
    const auto exported =
        RunFitcal(dir, "export ros2-control --calibration " + cal +
                           " --controller diff_drive_controller --out " + dir.Path("ctrl.yaml"));
    EXPECT_EQ(exported.exit_code, 0) << exported.err;
    const auto compared =
        RunFitcal(dir, "compare --logs " + data +
                           " --methods ceres --repetitions 1 --quiet --out " + dir.Path("cmp"));
    EXPECT_EQ(compared.exit_code, 0) << compared.err;
  }
  // Not this command's output: refused with 2 and the file untouched, then replaced with --force.
  const std::string mine = dir.Write("mine.yaml", "my: notes\n");
  const auto refused = RunFitcal(dir, "export ros2-control --calibration " + cal +
                                          " --controller diff_drive_controller --out " + mine);
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_TRUE(Has(refused.err, "--force")) << refused.err;
  EXPECT_EQ(ReadFileBytes(mine), "my: notes\n");
  const auto fit_refused = RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + mine);
  EXPECT_EQ(fit_refused.exit_code, 2) << fit_refused.err;
  EXPECT_EQ(ReadFileBytes(mine), "my: notes\n");
  // compare writes three files from one prefix: one that is not its own stops all three.
  const std::string compare = "compare --logs " + data + " --methods ceres --repetitions 1 --quiet";
  dir.Write("mine.md", "my notes\n");
  const auto compare_refused = RunFitcal(dir, compare + " --out " + dir.Path("mine"));
  EXPECT_EQ(compare_refused.exit_code, 2) << compare_refused.err;
  EXPECT_EQ(testing::Lines(compare_refused.err), 1) << compare_refused.err;
  EXPECT_TRUE(Has(compare_refused.err, "mine.md") && Has(compare_refused.err, "--force"))
      << compare_refused.err;
  EXPECT_EQ(ReadFileBytes(dir.Path("mine.md")), "my notes\n");
  EXPECT_FALSE(fs::exists(dir.Path("mine.csv")));
  const auto compare_forced = RunFitcal(dir, compare + " --force --out " + dir.Path("mine"));
  EXPECT_EQ(compare_forced.exit_code, 0) << compare_forced.err;
  EXPECT_TRUE(Has(ReadFileBytes(dir.Path("mine.md")), "| Strategy | Method |"));
  const auto forced =
      RunFitcal(dir, "export ros2-control --calibration " + cal +
                         " --controller diff_drive_controller --force --out " + mine);
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_TRUE(Has(ReadFileBytes(mine), "diff_drive_controller:")) << ReadFileBytes(mine);
}

TEST(NewcomerCli, ADataSetGivenWithoutItsFlagIsPointedToLogs) {
  TempDir dir;
  const auto r = RunFitcal(dir, "fit " + kFlower);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "--logs " + kFlower)) << r.err;
}

// Raw recordings passed as --logs: the next step, not "dataset.yaml: cannot open file".
TEST(NewcomerCli, RawRecordingsAsLogsAreToldToImportFirst) {
  TempDir dir;
  dir.Write("raw/circular/221220201643/221220201643_metadata.csv", "type,diff\n");
  const auto r = RunFitcal(dir, "fit --logs " + dir.Path("raw/circular/221220201643"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "dataset.yaml")) << r.err;
  EXPECT_TRUE(Has(r.err, "fitcal import optiodom")) << r.err;
  const auto robot_folder =
      RunFitcal(dir, "report --logs " + dir.Path("raw") +
                         " --calibration " + FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml --out " +
                         dir.Path("rep"));
  EXPECT_TRUE(Has(robot_folder.err, "fitcal import optiodom")) << robot_folder.err;
  dir.Write("bag/metadata.yaml", "rosbag2_bagfile_information: {}\n");
  dir.Write("bag/bag_0.mcap", "");
  const auto bag = RunFitcal(dir, "fit --logs " + dir.Path("bag"));
  EXPECT_TRUE(Has(bag.err, "fitcal import rosbag2")) << bag.err;
  const auto empty = RunFitcal(dir, "fit --logs " + dir.Path("raw/circular"));
  EXPECT_TRUE(Has(empty.err, "import optiodom")) << empty.err;
}

// A robot's folder instead of its sessions: the session folders to pass.
TEST(NewcomerCli, ImportOfARobotFolderNamesTheSessionFolders) {
  TempDir dir;
  dir.Write("diff/circular/221220201643/221220201643_metadata.csv", "type,diff\n");
  dir.Write("diff/square/231220200029/231220200029_metadata.csv", "type,diff\n");
  const auto r = RunFitcal(dir, "import optiodom " + dir.Path("diff") + " --out " + dir.Path("o"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "not an OptiOdom session folder")) << r.err;
  EXPECT_TRUE(Has(r.err, dir.Path("diff/circular") + "/*")) << r.err;
  EXPECT_TRUE(Has(r.err, dir.Path("diff/square") + "/*")) << r.err;
  EXPECT_FALSE(fs::exists(dir.Path("o")));
}

// Everything imported together: the one free run trains, and fit says so.
TEST(NewcomerCli, AFamilyWithNoHeldOutRunIsSaidAloud) {
  if (!fs::is_directory(kDiff + "/free")) GTEST_SKIP() << "no " << kDiff;
  TempDir dir;
  const std::string d = dir.Path("all");
  const auto import = RunFitcal(dir, "import optiodom " + kDiff + "/circular/* " + kDiff +
                                         "/square/* " + kDiff + "/free/* --out " + d);
  ASSERT_EQ(import.exit_code, 0) << import.err;
  const auto fit = RunFitcal(dir, "fit --logs " + d + " --out " + dir.Path("cal.yaml"));
  EXPECT_TRUE(Has(fit.out, "note: all 1 run(s) of 'free' train and none is held out")) << fit.out;
  EXPECT_FALSE(Has(fit.out, "of 'circular' train")) << fit.out;
}

// The subcommands a --help lists ("Subcommands:" up to the next blank line), each the first word.
std::vector<std::string> SubcommandsIn(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream lines(help);
  std::string line;
  bool in_list = false;
  while (std::getline(lines, line)) {
    if (line == "Subcommands:") {
      in_list = true;
    } else if (in_list && line.empty()) {
      break;
    } else if (in_list) {
      std::istringstream words(line);
      std::string name;
      if (words >> name) names.push_back(name);
    }
  }
  return names;
}

// How often `needle` occurs in `text`.
int Occurrences(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos;
       at = text.find(needle, at + needle.size())) {
    ++n;
  }
  return n;
}

// Every command's help ends with the one list of exit statuses (once), names no source header and
// no README section that is not there, and carries no parser artefact: no "{false}" of a negated
// flag, no "Excludes:"/"Needs:" glued after an option's name. The commands are those the helps
// list, so a command added later is checked without naming it here.
TEST(NewcomerCli, EveryHelpListsTheExitStatusesAndNoArtefacts) {
  TempDir dir;
  std::vector<std::string> commands{""};
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const std::string command = commands[i];
    SCOPED_TRACE("fitcal " + command + " --help");
    const auto r = RunFitcal(dir, command + " --help");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(Occurrences(r.out, "Exit status: 0 success; 1 bad input"), 1) << r.out;
    EXPECT_TRUE(Has(r.out, "5 no calibration beats the nominal robot")) << r.out;
    for (const char* artefact :
         {"{false}", "{true}", "Excludes:", "Needs:", ".h)", "README.md, Simulator"}) {
      EXPECT_FALSE(Has(r.out, artefact)) << artefact << " in\n" << r.out;
    }
    for (const std::string& sub : SubcommandsIn(r.out)) {
      commands.push_back(command.empty() ? sub : command + " " + sub);
    }
  }
  // The 11 commands and 2 groups of cli/command_line.cc, the top level and import's, export's own.
  EXPECT_EQ(commands.size(), 14u);
  // The exclusion is said in words (and still refused: InputClassesCli.UsageErrors...).
  for (const std::string command : {"fit", "diagnose"}) {
    const auto help = RunFitcal(dir, command + " --help");
    EXPECT_TRUE(Has(help.out, "(not with --train-reps)")) << help.out;
    EXPECT_TRUE(Has(help.out, "(not with --train-trajectories)")) << help.out;
  }
  const auto fleet = RunFitcal(dir, "fleet --help");
  EXPECT_TRUE(Has(fleet.out, "Columns: unit")) << fleet.out;
  EXPECT_TRUE(Has(fleet.out, "judged on different held-out runs")) << fleet.out;
}

}  // namespace
}  // namespace fitcal
