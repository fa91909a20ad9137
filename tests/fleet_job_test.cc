// The Kubernetes fleet Job's script (deploy/k8s/fitcal-fleet-job.yaml runs deploy/k8s/fleet-index.sh
// in every pod) run here as the Job runs it: one process per index, JOB_COMPLETION_INDEX set, the
// volume a directory, the summary's index started first so that it has to wait for the others.
// Three simulated robots: two calibrate; the third's held-out runs were driven by another robot
// (the nominal one, as after a wheel change in mid-session), which fit must refuse (exit 5).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>
#include <thread>

#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::FitcalRun;
using testing::Has;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;

const std::string kRobot = std::string(FITCAL_SOURCE_DIR) + "/data/robots/apr02.yaml";
const std::string kScript = std::string(FITCAL_SOURCE_DIR) + "/deploy/k8s/fleet-index.sh";
constexpr const char* kDate = "2026-05-01";
// Six repetitions: fit's default split trains on 1-5 and judges on 6.
constexpr const char* kRepetitions = "6";

// apr02.yaml under another name: fleet tells robots apart by the calibration's name.
std::string NamedRobot(const TempDir& dir, const std::string& name) {
  std::string yaml = ReadFileBytes(kRobot);
  yaml.replace(yaml.find("name: apr02"), 11, "name: " + name);
  return dir.Write(name + ".yaml", yaml);
}

void Simulate(const TempDir& dir, const std::string& robot, const std::string& out,
              const std::string& extra) {
  const FitcalRun r = RunFitcal(dir, "simulate --robot " + robot + " --out " + out +
                                         " --repetitions " + kRepetitions + " " + extra);
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

// One index of the Job, as its pod runs it: its exit status and what it printed.
FitcalRun RunIndex(const TempDir& dir, const fs::path& fleet, int index) {
  const std::string log = dir.Path("index" + std::to_string(index) + ".txt");
  const std::string command = "env JOB_COMPLETION_INDEX=" + std::to_string(index) +
                              " RUN_ID=test-run RUN_DATE=" + kDate + " FLEET_DIR=" +
                              fleet.string() + " FLEET_POLL_S=1 FLEET_WAIT_S=240 PATH=" +
                              FITCAL_BINARY_DIR + "/tools:/usr/bin:/bin sh " + kScript + " > " +
                              log + " 2>&1";
  const int status = std::system(command.c_str());
  FitcalRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = ReadFileBytes(log);
  return r;
}

TEST(FleetJob, ThreeRobotsOneRefusedLeaveTwoCalibrationsARefusalAndASummary) {
  TempDir dir;
  const fs::path fleet = dir.path() / "fleet";
  for (const char* name : {"robot-a", "robot-b"}) {
    Simulate(dir, NamedRobot(dir, name), (fleet / "data" / name).string(), "--seed 3");
  }
  // robot-c: repetitions 1-5 driven by the simulator's default truth (Palacin Table 5, R 12 %
  // longer than the nominal), repetition 6 by the nominal robot itself. The calibration learns
  // Table 5 and replays repetition 6 worse than the nominal does, exactly right there.
  const std::string c = NamedRobot(dir, "robot-c");
  const fs::path c_data = fleet / "data" / "robot-c";
  Simulate(dir, c, c_data.string(), "--seed 4");
  Simulate(dir, c, dir.Path("c-nominal"), "--seed 4 --truth " + c);
  int replaced = 0;
  for (const auto& f : fs::directory_iterator(dir.path() / "c-nominal" / "runs")) {
    if (f.path().filename().string().find("rep06") == std::string::npos) continue;
    fs::copy_file(f.path(), c_data / "runs" / f.path().filename(),
                  fs::copy_options::overwrite_existing);
    ++replaced;
  }
  ASSERT_EQ(replaced, 2 * 36);  // encoders and ground truth of the 36 flower trajectories
  dir.Write("fleet/datasets.txt", "data/robot-a\ndata/robot-b\ndata/robot-c\n");

  // Index 3 (the summary) first, in parallel: it must wait for the three robots' statuses.
  FitcalRun summary_index;
  std::thread summary([&] { summary_index = RunIndex(dir, fleet, 3); });
  const FitcalRun a = RunIndex(dir, fleet, 0), b = RunIndex(dir, fleet, 1),
                  refused = RunIndex(dir, fleet, 2);
  summary.join();
  EXPECT_EQ(a.exit_code, 0) << a.out;
  EXPECT_EQ(b.exit_code, 0) << b.out;
  EXPECT_EQ(refused.exit_code, 5) << refused.out;  // the Job's podFailurePolicy fails this index
  EXPECT_EQ(summary_index.exit_code, 0) << summary_index.out;

  for (const char* name : {"robot-a", "robot-b"}) {
    const fs::path result = fleet / "results" / name / kDate;
    ASSERT_TRUE(fs::exists(result / "cal.yaml")) << name;
    EXPECT_TRUE(fs::exists(result / "report" / "metrics.json")) << name;
    EXPECT_EQ(ReadFileBytes(result / "exit_status"), "0\n");
    // A calibration, not a copy of the nominal: wheel a's distance recovers Table 5's R_a =
    // 0.2186 m from the nominal 0.195 m (fitcal_cli_test's tolerance on two repetitions; five
    // here only shrink the sigma, ~0.5 mm).
    EXPECT_NEAR(YAML::LoadFile((result / "cal.yaml").string())["wheels"][0]["distance_m"]
                    .as<double>(), 0.2186, 0.003) << name;
  }
  const fs::path c_result = fleet / "results" / "robot-c" / kDate;
  EXPECT_FALSE(fs::exists(c_result / "cal.yaml"));
  EXPECT_FALSE(fs::exists(c_result / "report"));
  EXPECT_EQ(ReadFileBytes(c_result / "exit_status"), "5\n");
  EXPECT_TRUE(Has(ReadFileBytes(c_result / "fit.txt"), "nominal")) << ReadFileBytes(c_result / "fit.txt");

  const std::string text = ReadFileBytes(fleet / "summary" / (std::string(kDate) + ".txt"));
  EXPECT_TRUE(Has(text, "  0 robot-a 0\n  1 robot-b 0\n  2 robot-c 5\n")) << text;
  EXPECT_TRUE(Has(text, "\nrobot-a\n")) << text;  // fleet's table, one block per robot
  EXPECT_TRUE(Has(text, "\nrobot-b\n")) << text;
  EXPECT_FALSE(Has(text, "\nrobot-c\n")) << text;
  EXPECT_EQ(summary_index.out, text);  // the pod's log shows it too
}

// The summary does not wait forever for a robot whose pod died without a status, and says which;
// an index beyond the list is a misconfigured Job (completions = robots + 1), refused in one line.
TEST(FleetJob, SummaryNamesMissingRobotsAndAnIndexBeyondTheListIsRefused) {
  TempDir dir;
  const fs::path fleet = dir.path() / "fleet";
  dir.Write("fleet/datasets.txt", "data/robot-a\ndata/robot-b\n");
  Simulate(dir, NamedRobot(dir, "robot-a"), (fleet / "data" / "robot-a").string(), "--seed 3");
  ASSERT_EQ(RunIndex(dir, fleet, 0).exit_code, 0);
  const std::string log = dir.Path("summary.txt");
  const std::string command = "env JOB_COMPLETION_INDEX=2 RUN_ID=test-run RUN_DATE=" +
                              std::string(kDate) + " FLEET_DIR=" + fleet.string() +
                              " FLEET_POLL_S=1 FLEET_WAIT_S=1 PATH=" + FITCAL_BINARY_DIR +
                              "/tools:/usr/bin:/bin sh " + kScript + " > " + log + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << ReadFileBytes(log);
  const std::string text = ReadFileBytes(fleet / "summary" / (std::string(kDate) + ".txt"));
  EXPECT_TRUE(Has(text, "  0 robot-a 0\n  1 (no status)\n")) << text;
  EXPECT_TRUE(Has(ReadFileBytes(log), "no status from index 1 after 1 s")) << ReadFileBytes(log);

  const FitcalRun beyond = RunIndex(dir, fleet, 3);
  EXPECT_EQ(beyond.exit_code, 2);
  EXPECT_EQ(beyond.out, "fleet-index.sh: index 3, but " + (fleet / "datasets.txt").string() +
                            " lists 2 data sets: completions must be 3\n");
}

}  // namespace
}  // namespace fitcal
