// Nothing lost: a previous calibrated YAML survives an interrupted or refused run, and
// `--out` does not silently replace another robot's calibration. Drives the fitcal binary on a
// data set written by `fitcal simulate`.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "io/calibration_block.h"
#include "io/dataset.h"
#include "io/log_files.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/test_files.h"
#include "tests/omni3_robot.h"
#include "tests/three_wheel_files.h"

namespace fitcal {
namespace nothing_lost_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

namespace fs = std::filesystem;
using testing::ReadFileBytes;
using testing::TempDir;
using testing::WriteFileBytes;

const std::string kFitcal = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal";
const std::string kRobot = std::string(FITCAL_SOURCE_DIR) + "/data/robots/apr02.yaml";

int RunShell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

fs::path Simulate(const fs::path& root, int repetitions) {
  const fs::path data = root / "data";
  EXPECT_EQ(RunShell(kFitcal + " simulate --robot '" + kRobot + "' --out '" + data.string() +
                     "' --repetitions " + std::to_string(repetitions) + " > /dev/null"),
            0);
  return data;
}

// Files in `dir` other than the listed ones (temporaries left behind).
std::vector<std::string> Leftovers(const fs::path& dir, const std::vector<std::string>& expected) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (std::find(expected.begin(), expected.end(), name) == expected.end()) out.push_back(name);
  }
  return out;
}

// A calibrated YAML of robot `name` to be preserved.
std::string PreviousOutput(const std::string& name) {
  Omni3Robot robot = ReadOmni3Robot(kRobot);
  robot.name = name;
  const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(robot);
  io::CalibrationBlock record;
  record.method = "ceres";
  record.termination = "CONVERGENCE";
  return model->RobotYaml(model->robot().nominal, io::CalibrationBlockYaml(record, model->robot()));
}

// Starts `fitcal args...`, stopped (SIGSTOP) at `stage` by io::StopHereForTests. Returns the
// child's pid, or -1 when it ended without reaching the stage.
pid_t StartStoppedAt(const std::vector<std::string>& args, const char* stage) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    setenv("FITCAL_TEST_STOP_AT", stage, 1);
    std::vector<char*> argv{const_cast<char*>("fitcal")};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(kFitcal.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, WUNTRACED) != pid || !WIFSTOPPED(status)) return -1;
  return pid;
}

std::vector<std::string> TemporaryFiles(const fs::path& dir) {
  std::vector<std::string> out = Leftovers(dir, {"calibrated.yaml"});
  std::sort(out.begin(), out.end());
  return out;
}

// The signal lands at a known stage (after loading, after fitting, and between writing the
// temporary file and renaming it over the output), not after a guessed delay, so the test does
// not depend on how fast the machine is.
TEST(NothingLostTest, SignalAtEveryStageLeavesThePreviousOutputUntouched) {
  const TempDir scratch;
  const fs::path data = Simulate(scratch.path(), 2);
  const fs::path out_dir = scratch.path() / "out";
  fs::create_directories(out_dir);
  const fs::path out = out_dir / "calibrated.yaml";
  const std::string previous = PreviousOutput("apr02");
  for (const char* stage : {"loaded", "fitted", "temporary-written"}) {
    for (int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGKILL}) {
      SCOPED_TRACE(std::string("signal ") + strsignal(signal_number) + " at stage " + stage);
      WriteFileBytes(out, previous);
      const pid_t pid = StartStoppedAt({"--logs", data.string(), "--out", out.string()}, stage);
      ASSERT_GT(pid, 0) << "fitcal ended before reaching the stage";
      if (std::string(stage) == "temporary-written") {
        ASSERT_EQ(TemporaryFiles(out_dir).size(), 1u) << "the stage is not where it claims";
      }
      kill(pid, signal_number);
      kill(pid, SIGCONT);
      int status = 0;
      ASSERT_EQ(waitpid(pid, &status, 0), pid);
      ASSERT_TRUE(WIFSIGNALED(status)) << "the signal did not end fitcal";
      EXPECT_EQ(WTERMSIG(status), signal_number) << "the handler must re-raise the signal";
      EXPECT_EQ(ReadFileBytes(out), previous) << "the previous output was changed";
      const std::vector<std::string> temporaries = TemporaryFiles(out_dir);
      if (signal_number == SIGKILL && std::string(stage) == "temporary-written") {
        // Uncatchable: the temporary stays (named after the output), the output is intact.
        ASSERT_EQ(temporaries.size(), 1u);
        EXPECT_EQ(temporaries[0].rfind(".calibrated.yaml.tmp-", 0), 0u) << temporaries[0];
        fs::remove(out_dir / temporaries[0]);
      } else {
        EXPECT_TRUE(temporaries.empty()) << "temporary file left: " << temporaries[0];
      }
    }
  }
  // Not stopped: the run completes and replaces the output with a readable calibration.
  WriteFileBytes(out, previous);
  ASSERT_EQ(RunShell(kFitcal + " --logs '" + data.string() + "' --out '" + out.string() +
                     "' > /dev/null"),
            0);
  EXPECT_NE(ReadFileBytes(out), previous);
  EXPECT_NO_THROW(ReadOmni3Robot(out.string()));
  EXPECT_TRUE(TemporaryFiles(out_dir).empty());
}

TEST(NothingLostTest, RefusedFitLeavesThePreviousOutputUntouched) {
  // Failure after loading, before any output: miswired encoder columns (a and b swapped).
  const TempDir scratch;
  const fs::path data = Simulate(scratch.path(), 1);
  const io::Dataset dataset = io::LoadDataset(data.string());
  const io::DatasetIndex index = io::ReadDatasetIndex(data.string());
  for (std::size_t i = 0; i < index.runs.size(); ++i) {
    EncoderLog log = dataset.runs[i].encoders;
    for (auto&& s : log.samples) std::swap(s.value[0], s.value[1]);
    WriteFileBytes(index.runs[i].encoders_path, io::EncoderCsv(log));
  }
  const fs::path out = scratch.path() / "calibrated.yaml";
  const std::string previous = PreviousOutput("apr02");
  WriteFileBytes(out, previous);
  const fs::path err = scratch.path() / "stderr.txt";
  EXPECT_EQ(RunShell(kFitcal + " --logs '" + data.string() + "' --out '" + out.string() +
                     "' > /dev/null 2> '" + err.string() + "'"),
            4);
  const std::string message = ReadFileBytes(err);
  EXPECT_NE(message.find("columns w_a and w_b swapped"), std::string::npos) << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_EQ(ReadFileBytes(out), previous);
}

TEST(NothingLostTest, OutRefusesAnotherRobotsCalibrationUnlessForced) {
  const TempDir scratch;
  const fs::path data = Simulate(scratch.path(), 1);
  const fs::path out = scratch.path() / "calibrated.yaml";
  const fs::path err = scratch.path() / "stderr.txt";
  const std::string fit =
      kFitcal + " --logs '" + data.string() + "' --train-reps 1 --out '" + out.string() + "'";
  const std::string quiet = " > /dev/null 2> '" + err.string() + "'";

  const std::string other = PreviousOutput("apr03");
  WriteFileBytes(out, other);
  EXPECT_EQ(RunShell(fit + quiet), 2);
  EXPECT_NE(ReadFileBytes(err).find("holds the calibration of robot 'apr03', not 'apr02'"),
            std::string::npos)
      << ReadFileBytes(err);
  EXPECT_EQ(ReadFileBytes(out), other);

  WriteFileBytes(out, "not: [a robot\n");  // not even YAML: refused as well
  EXPECT_EQ(RunShell(fit + quiet), 2);
  EXPECT_NE(ReadFileBytes(err).find("is not a robot YAML"), std::string::npos)
      << ReadFileBytes(err);

  WriteFileBytes(out, other);
  EXPECT_EQ(RunShell(fit + " --force" + quiet), 0) << ReadFileBytes(err);
  EXPECT_EQ(ReadOmni3Robot(out.string()).name, "apr02");

  // The same robot's previous calibration is replaced without --force.
  const std::string same = PreviousOutput("apr02");
  WriteFileBytes(out, same);
  EXPECT_EQ(RunShell(fit + quiet), 0) << ReadFileBytes(err);
  EXPECT_NE(ReadFileBytes(out), same);
}

// The fit of every model refuses them (validation/rate_units.h), naming the likely unit.
TEST(NothingLostTest, RatesInDegreesPerSecondAreNamedAndRefused) {
  const TempDir scratch;
  const fs::path data = Simulate(scratch.path(), 1);
  const io::DatasetIndex index = io::ReadDatasetIndex(data.string());
  // One run in degrees/s is enough to be told (the check pools path lengths over runs, and a
  // 57x longer odometry path dominates).
  for (std::size_t i = 0; i < index.runs.size(); ++i) {
    EncoderLog log = io::ReadEncoderCsv(index.runs[i].encoders_path);
    for (auto&& s : log.samples) {
      for (int w = 0; w < 3; ++w) s.value[w] *= 180.0 / M_PI;
    }
    WriteFileBytes(index.runs[i].encoders_path, io::EncoderCsv(log));
  }
  const fs::path err = scratch.path() / "stderr.txt";
  EXPECT_NE(RunShell(kFitcal + " --logs '" + data.string() + "' --no-output > /dev/null 2> '" +
                     err.string() + "'"),
            0);
  EXPECT_NE(ReadFileBytes(err).find("not in rad/s (they look like deg/s)"), std::string::npos)
      << ReadFileBytes(err);
}

// report/ is written as a set (its files refer to each other): staged in a sibling directory and renamed over
// the previous report. A signal in the middle, or a write that fails (RLIMIT_FSIZE: EFBIG, as a
// full disk gives ENOSPC), leaves the previous report byte for byte: never index.html of one run
// beside metrics.json of another.
std::map<std::string, std::string> DirectoryBytes(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    out[e.path().filename().string()] = ReadFileBytes(e.path());
  return out;
}

TEST(NothingLostTest, ReportDirectoryIsReplacedWholeOrNotAtAll) {
  const TempDir scratch;
  const fs::path data = Simulate(scratch.path(), 2);
  const fs::path cal = scratch.path() / "cal.yaml";
  ASSERT_EQ(RunShell(kFitcal + " --logs '" + data.string() + "' --train-reps 1 --out '" +
                     cal.string() + "' > /dev/null"),
            0);
  // The next report is of a calibration of the other repetition (report never judges one on
  // its own training runs, so --train-reps 2 on `cal` is refused): every file differs.
  const fs::path other = scratch.path() / "other.yaml";
  ASSERT_EQ(RunShell(kFitcal + " --logs '" + data.string() + "' --train-reps 2 --out '" +
                     other.string() + "' > /dev/null"),
            0);
  const fs::path report = scratch.path() / "report";
  const std::string base = kFitcal + " report --logs '" + data.string() + "' --out '" +
                           report.string() + "' --calibration ";
  ASSERT_EQ(RunShell(base + "'" + cal.string() + "' > /dev/null"), 0);
  const auto previous = DirectoryBytes(report);
  ASSERT_EQ(previous.size(), 4u);
  const auto siblings = [&] {
    return Leftovers(scratch.path(), {"data", "cal.yaml", "other.yaml", "report"});
  };

  // The next report differs, so a mix would show.
  for (int signal_number : {SIGTERM, SIGKILL}) {
    SCOPED_TRACE(strsignal(signal_number));
    const pid_t pid = StartStoppedAt({"report", "--logs", data.string(), "--calibration",
                                      other.string(), "--out", report.string()},
                                     "report-staged");
    ASSERT_GT(pid, 0);
    ASSERT_EQ(siblings().size(), 1u) << "no staged directory beside the report";
    kill(pid, signal_number);
    kill(pid, SIGCONT);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(DirectoryBytes(report), previous) << "the previous report was changed";
    if (signal_number == SIGKILL) {  // uncatchable: the staged sibling stays, named after it
      ASSERT_EQ(siblings().size(), 1u);
      EXPECT_EQ(siblings()[0].rfind(".report.tmp-", 0), 0u) << siblings()[0];
      fs::remove_all(scratch.path() / siblings()[0]);
    } else {
      EXPECT_TRUE(siblings().empty()) << siblings()[0];
    }
  }
  // A write that fails: files larger than 8 kB cannot be written (EFBIG; SIGXFSZ ignored).
  const fs::path err = scratch.path() / "err.txt";
  EXPECT_EQ(RunShell("trap '' XFSZ; ulimit -f 8; " + base + "'" + other.string() +
                     "' > /dev/null 2> '" +
                     err.string() + "'"),
            1);
  EXPECT_NE(ReadFileBytes(err).find("cannot write"), std::string::npos) << ReadFileBytes(err);
  fs::remove(err);
  EXPECT_EQ(DirectoryBytes(report), previous);
  EXPECT_TRUE(siblings().empty()) << siblings()[0];
  // Uninterrupted: replaced as a whole.
  ASSERT_EQ(RunShell(base + "'" + other.string() + "' > /dev/null"), 0);
  const auto next = DirectoryBytes(report);
  ASSERT_EQ(next.size(), 4u);
  for (const auto& [name, bytes] : next) EXPECT_NE(bytes, previous.at(name)) << name;
  EXPECT_TRUE(siblings().empty());
}

}  // namespace
}  // namespace fitcal
