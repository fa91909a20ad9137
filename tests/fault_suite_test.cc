// The fault suite, written from classes of fault rather than from cases (issue 31, item 5):
//   - every file format fitcal reads, truncated at many offsets and with bytes flipped (seeded):
//     the loaders accept it or refuse it with one line, never crash or hang;
//   - YAML that expands itself through aliases or nests without end: refused at once;
//   - an output that is, holds or sits inside an input, --force or not: refused, inputs intact;
//   - a directory --force would replace that fitcal did not write: refused, files intact;
//   - a file-size limit (RLIMIT_FSIZE): one line, exit 1, no signal, nothing left;
//   - a read-only output directory (skipped as root, whom chmod does not stop);
//   - a writer killed (SIGKILL) after a growing delay: the previous output intact or the new one
//     complete, no temporary visible as an output, and the next writer removes what was left;
//   - two writers of one output at once: one complete output, nothing mixed.
// Time is bounded by construction: fixed numbers of mutations and delays, small data sets.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "models/asoc/asoc_files.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/yaml_reader.h"
#include "io/yaml_text.h"
#include "models/model_registry.h"
#include "tests/asoc_robot_file.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::Lines;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;
using testing::WriteFileBytes;

const std::string kFitcal = std::string(FITCAL_BINARY_DIR) + "/tools/fitcal";

// Every file below `dir` with its bytes: what must survive a refused or interrupted command.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) {
      files[e.path().lexically_relative(dir).string()] = ReadFileBytes(e.path());
    }
  }
  return files;
}

// A small simulated data set of `model` (2 repetitions; a second or so to write).
fs::path SimulatedDataset(const TempDir& dir, const std::string& name, const std::string& model,
                          int seed = 1) {
  const fs::path data = dir.path() / name;
  const auto r = RunFitcal(dir, "simulate --model " + model + " --repetitions 2 --seed " +
                                    std::to_string(seed) + " --out '" + data.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return data;
}

// Loads the data set the way every command does: index, robot file, every run.
void LoadEverything(const fs::path& data) {
  const io::DatasetIndex index = io::ReadDatasetIndex(data.string(), {});
  const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
  io::DatasetOptions options;
  options.num_threads = 1;
  io::LoadDataset(index, model->robot(), options);
}

// ---------------------------------------------------------------------------------------------
// Truncated and garbage files of every format.

// Mutants of `bytes`: truncations at kCuts offsets spread over the file (and at 0), and copies
// with kFlips random bytes replaced by random values, from a fixed seed.
std::vector<std::string> Mutants(const std::string& bytes, std::uint32_t seed) {
  constexpr int kCuts = 12, kFlips = 12;
  std::vector<std::string> out;
  for (int i = 0; i < kCuts; ++i) out.push_back(bytes.substr(0, bytes.size() * i / kCuts));
  std::mt19937 rng(seed);
  for (int i = 0; i < kFlips && !bytes.empty(); ++i) {
    std::string m = bytes;
    for (int k = 0; k < 1 + i % 4; ++k) {
      m[std::uniform_int_distribution<std::size_t>(0, m.size() - 1)(rng)] =
          static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    }
    out.push_back(m);
  }
  return out;
}

// Every format a data set holds, for the models with their own readers and channels.
TEST(FaultSuiteTest, TruncatedAndGarbledFilesOfEveryFormatFailInOneLine) {
  const TempDir dir;
  for (const char* model : {"diff_drive", "tricycle", "omni"}) {
    SCOPED_TRACE(model);
    const fs::path data = SimulatedDataset(dir, std::string("ds_") + model, model);
    ASSERT_NO_THROW(LoadEverything(data));
    const io::DatasetIndex index = io::ReadDatasetIndex(data.string(), {});
    const std::vector<std::string> files = {index.yaml_path, index.robot_path,
                                            index.runs.front().encoders_path,
                                            index.runs.front().ground_truth_path};
    std::uint32_t seed = 1;
    for (const std::string& file : files) {
      const std::string original = ReadFileBytes(file);
      for (const std::string& mutant : Mutants(original, seed++)) {
        WriteFileBytes(file, mutant);
        try {
          LoadEverything(data);
        } catch (const std::exception& e) {
          const std::string what = e.what();
          EXPECT_FALSE(what.empty()) << file;
          EXPECT_EQ(what.find('\n'), std::string::npos) << file << ": " << what;
        }
      }
      WriteFileBytes(file, original);
    }
  }
}

// The calibration a fit writes (a robot YAML with its calibration block, read by report and
// export) and the ASOC data set's own formats (robot YAML, three-castor encoder CSV).
TEST(FaultSuiteTest, TruncatedAndGarbledCalibrationsAndAsocFilesFailInOneLine) {
  const TempDir dir;
  const fs::path data = SimulatedDataset(dir, "ds", "diff_drive");
  const fs::path cal = dir.path() / "cal.yaml";
  ASSERT_EQ(RunFitcal(dir, "fit --logs " + data.string() + " --out " + cal.string()).exit_code, 0);
  const fs::path asoc = dir.path() / "asoc";
  ASSERT_EQ(RunFitcal(dir, "simulate --model asoc --out " + asoc.string()).exit_code, 0);
  const io::DatasetIndex asoc_index = io::ReadDatasetIndex(asoc.string(), {});
  const auto expect_one_line = [](const std::function<void()>& read) {
    try {
      read();
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_FALSE(what.empty());
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  const std::vector<std::pair<std::string, std::function<void()>>> files = {
      {cal.string(),
       [&] {
         ReadRobotModelFile(cal.string());
         io::ReadCalibrationProvenance(cal.string());
       }},
      {asoc_index.robot_path, [&] { io::ReadAsocRobot(asoc_index.robot_path); }},
      {asoc_index.runs.front().encoders_path, [&] { LoadEverything(asoc); }},
  };
  std::uint32_t seed = 100;
  for (const auto& [file, read] : files) {
    SCOPED_TRACE(file);
    const std::string original = ReadFileBytes(file);
    for (const std::string& mutant : Mutants(original, seed++)) {
      WriteFileBytes(file, mutant);
      expect_one_line(read);
    }
    WriteFileBytes(file, original);
  }
}

// yaml-cpp resolves an alias to the node it names: nine lines that repeat each other make 10^9
// nodes for whoever walks the document. Refused when read, in bounded time.
TEST(FaultSuiteTest, YamlThatExpandsItselfOrNestsWithoutEndIsRefused) {
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 9; ++i) {
    bomb += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) bomb += std::string(k ? ", " : "") + "*a" + std::to_string(i - 1);
    bomb += "]\n";
  }
  try {
    io::ParseYaml(bomb, "bomb.yaml");
    ADD_FAILURE() << "an alias bomb was accepted";
  } catch (const io::InputError& e) {
    EXPECT_EQ(e.kind(), io::InputErrorKind::kTooLarge) << e.what();
  }
  const std::string deep = std::string(200, '[') + std::string(200, ']');
  EXPECT_THROW(io::ParseYaml(deep, "deep.yaml"), io::InputError);
  const std::string deeper = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_THROW(io::ParseYaml(deeper, "deeper.yaml"), io::InputError);
}

// ---------------------------------------------------------------------------------------------
// Nothing lost: outputs against inputs, and directories fitcal did not write.

struct OutputCase {
  std::string args;  // {data}, {cal}, {user} are replaced
  const char* what;
};

TEST(FaultSuiteTest, NoOutputMayBeHoldOrSitInsideAnInputForceOrNot) {
  const TempDir dir;
  const fs::path data = SimulatedDataset(dir, "data", "diff_drive");
  const fs::path cal = dir.path() / "cal.yaml";
  ASSERT_EQ(
      RunFitcal(dir, "fit --logs '" + data.string() + "' --out '" + cal.string() + "'").exit_code,
      0);
  const io::DatasetIndex index = io::ReadDatasetIndex(data.string(), {});
  const std::string enc = index.runs.front().encoders_path;
  const std::string enc_prefix = enc.substr(0, enc.size() - 4);  // compare adds ".csv"
  const std::vector<OutputCase> cases = {
      {"fit --logs {data} --out {data}/robot.yaml --force", "fit over the robot file"},
      {"fit --logs {data} --out " + enc + " --force", "fit over a recording"},
      {"fit --logs {data} --out {data} --force", "fit over the data set"},
      {"fit --logs {data} --out {data}/cal.yaml", "fit inside the data set"},
      {"report --logs {data} --calibration {cal} --out {data}", "report over the data set"},
      {"report --logs {data} --calibration {cal} --out {data}/runs", "report over the runs"},
      {"report --logs {data} --calibration {cal} --out " + fs::path(enc).parent_path().string() +
           "/report",
       "report inside the data set"},
      {"report --logs {data} --calibration {cal} --out {cal}", "report over the calibration"},
      {"diagnose --logs {data} --out {data}", "diagnose over the data set"},
      {"diagnose --logs {data} --out " + fs::path(enc).parent_path().parent_path().string(),
       "diagnose over the data set's parent"},
      {"export ros2-control --calibration {cal} --out {cal}", "export over its calibration"},
      {"compare --logs {data} --out " + enc_prefix, "compare prefix onto a recording"},
      {"simulate --model diff_drive --out {data}/runs --force", "simulate into the data set"},
      {"simulate --model diff_drive --robot {cal} --out {cal} --force", "simulate over its robot"},
  };
  const auto before_data = Snapshot(data);
  const std::string before_cal = ReadFileBytes(cal);
  for (const OutputCase& c : cases) {
    SCOPED_TRACE(c.what);
    std::string args = c.args;
    for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
             {"{data}", data.string()}, {"{cal}", cal.string()}}) {
      for (std::size_t at; (at = args.find(key)) != std::string::npos;) {
        args.replace(at, key.size(), value);
      }
    }
    const auto r = RunFitcal(dir, args);
    EXPECT_NE(r.exit_code, 0) << args << "\n" << r.out;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_EQ(Snapshot(data), before_data) << "an input was changed";
    EXPECT_EQ(ReadFileBytes(cal), before_cal) << "the calibration was changed";
  }
}

TEST(FaultSuiteTest, ForceReplacesOnlyWhatFitcalWroteAsTheSameKind) {
  const TempDir dir;
  const fs::path user = dir.path() / "user";
  fs::create_directories(user / "runs");
  WriteFileBytes(user / "notes.txt", "mine\n");
  WriteFileBytes(user / "runs" / "x.csv", "mine too\n");
  const auto before = Snapshot(user);
  for (const std::string& command :
       {std::string("simulate --model diff_drive --repetitions 2"),
        std::string("simulate --model asoc"),
        std::string("simulate --repetitions 1 --robot ") + FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml"}) {
    for (const char* force : {"", " --force"}) {
      const auto r = RunFitcal(dir, command + force + " --out '" + user.string() + "'");
      EXPECT_EQ(r.exit_code, 2) << command << force << ": " << r.err;
      EXPECT_EQ(Lines(r.err), 1) << r.err;
      EXPECT_EQ(Snapshot(user), before) << command << force;
    }
  }
  // A data set fitcal wrote is replaced by running the command again, --force or not (README,
  // Outputs: issue 42); a file added to it makes it foreign.
  const fs::path data = SimulatedDataset(dir, "data", "diff_drive");
  EXPECT_EQ(RunFitcal(dir, "simulate --model diff_drive --repetitions 2 --out " + data.string())
                .exit_code,
            0);
  EXPECT_EQ(RunFitcal(dir, "simulate --model diff_drive --repetitions 2 --seed 2 --force --out " +
                               data.string())
                .exit_code,
            0);
  WriteFileBytes(data / "my_notes.txt", "keep\n");
  const auto with_notes = Snapshot(data);
  EXPECT_EQ(
      RunFitcal(dir, "simulate --model diff_drive --repetitions 2 --force --out " + data.string())
          .exit_code,
      2);
  EXPECT_EQ(Snapshot(data), with_notes);
}

// ---------------------------------------------------------------------------------------------
// Resource faults and interrupted writers, with the fitcal binary run as a child.

struct ChildResult {
  bool exited = false;
  int code = -1;
  int signal = 0;
};

// Runs fitcal with `args` (and RLIMIT_FSIZE `max_file_bytes` when > 0); stdout and stderr to
// files in `dir`; SIGKILL after `kill_after` when given.
ChildResult RunChild(const std::vector<std::string>& args, const fs::path& dir,
                     long max_file_bytes = 0,
                     std::chrono::microseconds kill_after = std::chrono::microseconds(-1)) {
  const std::string out = (dir / "child.out").string(), err = (dir / "child.err").string();
  const pid_t pid = fork();
  if (pid == 0) {
    if (max_file_bytes > 0) {
      const rlimit limit{static_cast<rlim_t>(max_file_bytes), static_cast<rlim_t>(max_file_bytes)};
      setrlimit(RLIMIT_FSIZE, &limit);
    }
    if (!std::freopen(out.c_str(), "w", stdout) || !std::freopen(err.c_str(), "w", stderr)) {
      _exit(126);
    }
    std::vector<char*> argv{const_cast<char*>("fitcal")};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(kFitcal.c_str(), argv.data());
    _exit(127);
  }
  if (kill_after.count() >= 0) {
    std::this_thread::sleep_for(kill_after);
    kill(pid, SIGKILL);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ChildResult r;
  r.exited = WIFEXITED(status);
  r.code = r.exited ? WEXITSTATUS(status) : -1;
  r.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  return r;
}

// Names in `dir` that are not hidden: what a user sees as outputs.
std::set<std::string> VisibleNames(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.front() != '.') names.insert(name);
  }
  return names;
}

std::set<std::string> AllNames(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(FaultSuiteTest, AFileSizeLimitIsOneLineAndExitOneWithNothingLeft) {
  const TempDir dir;
  const fs::path work = dir.path() / "work";
  fs::create_directories(work);
  // A data set (a directory of files) and a calibration (one file), each larger than 2 kB.
  const fs::path data = work / "data";
  ChildResult r =
      RunChild({"simulate", "--model", "diff_drive", "--repetitions", "2", "--out", data.string()},
               dir.path(), 2048);
  EXPECT_TRUE(r.exited) << "killed by signal " << r.signal;
  EXPECT_EQ(r.code, 1);
  const std::string err = ReadFileBytes(dir.path() / "child.err");
  EXPECT_EQ(Lines(err), 1) << err;
  EXPECT_NE(err.find("File too large"), std::string::npos) << err;
  EXPECT_EQ(AllNames(work), std::set<std::string>{}) << "something was left";

  const fs::path good = SimulatedDataset(dir, "good", "diff_drive");
  const fs::path cal = work / "cal.yaml";
  WriteFileBytes(cal, "previous\n");
  r = RunChild({"fit", "--logs", good.string(), "--out", cal.string(), "--force"}, dir.path(),
               1024);
  EXPECT_TRUE(r.exited) << "killed by signal " << r.signal;
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(Lines(ReadFileBytes(dir.path() / "child.err")), 1);
  EXPECT_EQ(ReadFileBytes(cal), "previous\n");
  EXPECT_EQ(AllNames(work), std::set<std::string>{"cal.yaml"});
}

// A place nobody may write, root included (procfs): one line naming --out, exit 1, no signal.
TEST(FaultSuiteTest, AnUnwritableLocationIsOneLineNamingTheOutput) {
  const TempDir dir;
  const fs::path data = SimulatedDataset(dir, "ds", "diff_drive");
  for (const std::string& args :
       {std::string("simulate --model diff_drive --out /proc/self/fitcal_data"),
        "fit --logs " + data.string() + " --out /proc/self/fitcal_cal.yaml",
        "report --logs " + data.string() + " --calibration " + (data / "robot.yaml").string() +
            " --out /proc/self/fitcal_report"}) {
    const auto r = RunFitcal(dir, args);
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("/proc/self/fitcal_"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find(".tmp-"), std::string::npos) << "names a temporary: " << r.err;
  }
}

TEST(FaultSuiteTest, AReadOnlyOutputDirectoryIsOneLineAndExitOne) {
  if (geteuid() == 0) GTEST_SKIP() << "root writes into read-only directories";
  const TempDir dir;
  const fs::path ro = dir.path() / "ro";
  fs::create_directories(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  const auto r =
      RunFitcal(dir, "simulate --model diff_drive --out '" + (ro / "data").string() + "'");
  fs::permissions(ro, fs::perms::owner_all);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(fs::is_empty(ro));
}

// Puts `files` back as the whole content of `out` (a directory) or as `out` itself (a file, key
// "").
void Restore(const fs::path& out, const std::map<std::string, std::string>& files) {
  fs::remove_all(out);
  for (const auto& [name, bytes] : files) {
    const fs::path p = name.empty() ? out : out / name;
    fs::create_directories(p.parent_path());
    WriteFileBytes(p, bytes);
  }
}

std::map<std::string, std::string> OutputSnapshot(const fs::path& out) {
  if (fs::is_directory(out)) return Snapshot(out);
  return {{"", ReadFileBytes(out)}};
}

// One writer of each kind: a data set (simulate; import optiodom when the recordings are there),
// a calibration file (fit) and a report directory. `old_args` writes the previous output,
// `new_args` a different one over it; `complete` says whether an output is a whole new one.
struct KilledWriter {
  std::string name;
  std::vector<std::string> old_args, new_args;
  std::function<bool(const fs::path&)> complete;
};

// SIGKILL after delays from nothing to past the end of the write: at every point the output is
// the previous one byte for byte or the new one complete; a temporary left by the kill is hidden,
// and the next writer of the same output removes it.
TEST(FaultSuiteTest, AWriterKilledAtAnyMomentLeavesTheOldOutputOrTheNew) {
  const TempDir dir;
  const fs::path data = SimulatedDataset(dir, "input", "diff_drive");
  const fs::path work = dir.path() / "work";
  fs::create_directories(work);
  const fs::path out = work / "out";
  const std::string o = out.string(), d = data.string();
  const auto loads = [](const fs::path& p) {
    try {
      LoadEverything(p);
      return true;
    } catch (const std::exception&) {
      return false;
    }
  };
  std::vector<KilledWriter> writers = {
      {"simulate",
       {"simulate", "--model", "diff_drive", "--repetitions", "2", "--seed", "7", "--out", o},
       {"simulate", "--model", "diff_drive", "--repetitions", "2", "--seed", "8", "--force",
        "--out", o},
       loads},
      {"fit",
       {"fit", "--logs", d, "--train-reps", "1", "--out", o},
       {"fit", "--logs", d, "--train-reps", "1-2", "--out", o},
       [](const fs::path& p) {
         return ReadFileBytes(p).find("calibration:") != std::string::npos;
       }},
      // Two calibrations, each of one repetition, judged on the other (report never judges a
      // calibration on the runs it was fitted on).
      {"report",
       {"report", "--logs", d, "--calibration", (dir.path() / "cal.yaml").string(), "--out", o},
       {"report", "--logs", d, "--calibration", (dir.path() / "cal2.yaml").string(), "--out", o},
       [](const fs::path& p) {
         return fs::exists(p / "index.html") && fs::exists(p / "metrics.csv");
       }},
  };
  const fs::path sessions = fs::path(FITCAL_SHARED_DIR) / "data/optiodom/diff/free";
  if (fs::is_directory(sessions)) {
    std::vector<std::string> import = {"import", "optiodom"};
    for (const auto& e : fs::directory_iterator(sessions)) import.push_back(e.path().string());
    import.insert(import.end(), {"--out", o});
    std::vector<std::string> again = import;
    again.push_back("--force");
    writers.push_back({"import optiodom", import, again, loads});
  }
  for (const std::string reps : {"1", "2"}) {
    const std::string cal = (dir.path() / (reps == "1" ? "cal.yaml" : "cal2.yaml")).string();
    ASSERT_EQ(RunFitcal(dir, "fit --logs " + d + " --train-reps " + reps + " --out " + cal)
                  .exit_code,
              0);
  }
  for (const KilledWriter& w : writers) {
    SCOPED_TRACE(w.name);
    fs::remove_all(out);
    ASSERT_EQ(RunChild(w.old_args, dir.path()).code, 0) << ReadFileBytes(dir.path() / "child.err");
    const auto old_output = OutputSnapshot(out);
    for (int delay_ms : {0, 2, 8, 30, 100, 300}) {
      SCOPED_TRACE("SIGKILL after " + std::to_string(delay_ms) + " ms");
      Restore(out, old_output);
      RunChild(w.new_args, dir.path(), 0, std::chrono::milliseconds(delay_ms));
      EXPECT_EQ(VisibleNames(work), std::set<std::string>{"out"});
      if (OutputSnapshot(out) != old_output) {
        EXPECT_TRUE(w.complete(out)) << "a partial output";
      }
    }
    // Uninterrupted, the next writer replaces the output and removes what the kills left.
    Restore(out, old_output);
    EXPECT_EQ(RunChild(w.new_args, dir.path()).code, 0) << ReadFileBytes(dir.path() / "child.err");
    EXPECT_TRUE(w.complete(out));
    EXPECT_EQ(AllNames(work), std::set<std::string>{"out"}) << "a stale temporary was kept";
  }
}

// A catchable signal while a data set (a directory with runs/ below it) is being staged removes
// the whole staged tree: the handler walks it with system calls only.
TEST(FaultSuiteTest, ASignalWhileADataSetIsStagedLeavesNothing) {
  const TempDir dir;
  const fs::path work = dir.path() / "work";
  fs::create_directories(work);
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE(strsignal(signal_number));
    const pid_t pid = fork();
    if (pid == 0) {
      std::freopen("/dev/null", "w", stdout);
      setenv("FITCAL_TEST_STOP_AT", "temporary-written", 1);
      const std::string out = (work / "out").string();
      execl(kFitcal.c_str(), "fitcal", "simulate", "--model", "diff_drive", "--out", out.c_str(),
            static_cast<char*>(nullptr));
      _exit(127);
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, WUNTRACED), pid);
    ASSERT_TRUE(WIFSTOPPED(status)) << "fitcal ended before writing";
    EXPECT_EQ(AllNames(work).size(), 1u) << "no staged directory";
    kill(pid, signal_number);
    kill(pid, SIGCONT);
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(AllNames(work), std::set<std::string>{}) << "the staged data set was left";
  }
}

TEST(FaultSuiteTest, TwoWritersOfOneOutputLeaveOneCompleteOutput) {
  const TempDir dir;
  const fs::path work = dir.path() / "work";
  fs::create_directories(work);
  const fs::path out = work / "data";
  for (int round = 0; round < 3; ++round) {
    std::vector<std::thread> writers;
    for (const char* seed : {"1", "2"}) {
      writers.emplace_back([&, seed] {
        const fs::path own = dir.path() / (std::string("w") + seed);
        fs::create_directories(own);
        RunChild({"simulate", "--model", "diff_drive", "--repetitions", "2", "--seed", seed,
                  "--force", "--out", out.string()},
                 own);
      });
    }
    for (std::thread& w : writers) w.join();
    EXPECT_NO_THROW(LoadEverything(out));
    EXPECT_EQ(AllNames(work), std::set<std::string>{"data"});
  }
}

// ---------------------------------------------------------------------------------------------
// Names any YAML reader reads back the same.

TEST(FaultSuiteTest, RunIdsAndNamesRoundTripThroughAnyYamlReader) {
  const std::vector<std::string> names = {
      "007",  "1e3",  "0x1F",       "yes", "No",    "on",  "null", "~",          "a: b",
      "#tag", "it's", "say \"hi\"", "-",   "12:30", "[x]", "{y}",  "plain_name", ".inf"};
  std::vector<io::DatasetEntry> runs;
  for (std::size_t i = 0; i < names.size(); ++i) {
    runs.push_back(
        {names[i], names[i], static_cast<int>(i), "runs/" + names[i] + ".csv", "runs/gt.csv"});
  }
  const YAML::Node root = YAML::Load(io::DatasetYaml("robot: x.yaml", runs));
  EXPECT_EQ(root["robot"].as<std::string>(), "robot: x.yaml");
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(root["runs"][i]["id"].as<std::string>(), names[i]);
    EXPECT_EQ(root["runs"][i]["trajectory"].as<std::string>(), names[i]);
    // Plain only when a YAML 1.1 reader (booleans, sexagesimals, hex) would read a string too.
    EXPECT_EQ(io::IsSafePlainYaml(names[i]), names[i] == "plain_name") << names[i];
  }
}

}  // namespace
}  // namespace fitcal
