// Refusing what cannot be calibrated, before fitting (a fit would return nonsense silently): one test per class of
// data fitcal refuses. Each drives the fitcal binary on an otherwise valid data set with one
// defect and asserts the one line `fitcal: <file>[:line]: <what>` on stderr, the exit status (1
// bad input, 2 usage) and that nothing was written (no --out, no file created anywhere under the
// test's directory). The library-level tests beside them show the same check at the loader.

#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "io/warnings.h"
#include "io/yaml_reader.h"
#include "tests/test_files.h"
#include "tests/three_wheel_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using io::InputErrorKind;
using testing::FitcalRun;
using testing::Lines;
using testing::ListFiles;
using testing::ReadFileBytes;
using testing::RunFitcalOutside;
using testing::TempDir;
using testing::WriteFileBytes;

const fs::path kSource = FITCAL_SOURCE_DIR;

// An encoder log of constant rates (rad/s) at 100 Hz from t0 for `seconds`, and a ground truth
// that moves about as far as the apr02 robot's odometry of those rates (0.025 m per 0.1 s: the
// check before fitting refuses paths the bounds cannot relate, validation/rate_units.h): the two
// files of one run that loads.
std::string EncoderText(double t0, double seconds, double w) {
  std::string text = "t,w_a,w_b,w_c\n";
  char row[96];
  for (int k = 0; k * 0.01 <= seconds + 1e-9; ++k) {
    std::snprintf(row, sizeof row, "%.3f,%.3f,%.3f,%.3f\n", t0 + 0.01 * k, w, -w, 0.5 * w);
    text += row;
  }
  return text;
}
std::string GroundTruthText(double t0, double seconds, double y = 0.0) {
  std::string text = "t,x,y,theta\n";
  char row[96];
  for (int k = 0; k * 0.1 <= seconds + 1e-9; ++k) {
    std::snprintf(row, sizeof row, "%.3f,%.4f,%.4f,%.4f\n", t0 + 0.1 * k, 0.025 * k, y, 0.01 * k);
    text += row;
  }
  return text;
}

// A valid data set of three runs (repetitions 1-3) in <root>/ds; tests replace files in it.
class Fixture {
 public:
  Fixture() : dir_(temp_.path() / "ds") {
    fs::create_directories(dir_);
    fs::copy_file(kSource / "data" / "robots" / "apr02.yaml", dir_ / "robot.yaml");
    std::string yaml = "robot: robot.yaml\nruns:\n";
    for (int i = 1; i <= 3; ++i) {
      const std::string n = std::to_string(i);
      yaml += "  - {id: r" + n + ", trajectory: R1, repetition: " + n + ", encoders: enc" + n +
              ".csv, ground_truth: gt" + n + ".csv}\n";
      Write("enc" + n + ".csv", EncoderText(0.0, 2.0, 1.0 + 0.1 * i));
      Write("gt" + n + ".csv", GroundTruthText(0.0, 2.0, 0.1 * i));
    }
    Write("dataset.yaml", yaml);
  }
  void Write(const std::string& name, const std::string& text) const {
    WriteFileBytes(dir_ / name, text);
  }
  const fs::path& root() const { return temp_.path(); }
  const fs::path& dir() const { return dir_; }
  fs::path out() const { return temp_.path() / "calibrated.yaml"; }

 private:
  TempDir temp_;
  fs::path dir_;
};

// The fit command on the fixture must refuse: `exit_code`, exactly one stderr line that starts
// `fitcal: `, names `where` (file[:line]) and says `what`; nothing written or created.
void ExpectFitRefused(const Fixture& f, const std::string& where, const std::string& what,
                      int exit_code = 1, const std::string& out = "") {
  const std::string out_path = out.empty() ? f.out().string() : out;
  const std::set<std::string> before = ListFiles(f.root());
  const FitcalRun r = RunFitcalOutside(f.root(), "fit --logs '" + f.dir().string() + "' --out '" +
                                                     out_path + "' --threads 1 --train-reps 1-2");
  EXPECT_EQ(r.exit_code, exit_code) << r.err;
  ASSERT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("fitcal: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(where), std::string::npos) << "expected '" << where << "' in " << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << "expected '" << what << "' in " << r.err;
  EXPECT_LT(r.err.size(), 600u);
  if (out.empty()) {
    EXPECT_FALSE(fs::exists(f.out()));
  }
  EXPECT_EQ(ListFiles(f.root()), before) << "a file was created";
}

InputErrorKind LoadKind(const Fixture& f) {
  try {
    io::LoadDataset(f.dir().string());
  } catch (const io::InputError& e) {
    return e.kind();
  }
  ADD_FAILURE() << "loaded";
  return InputErrorKind::kMissingFile;
}

// The fixture is valid input: it loads, and the only objection to fitting it is that two runs
// (six final-pose residuals) cannot calibrate nine parameters (validation/residual_dof.h) - the
// refusals below all come before that, from the files themselves.
TEST(RefusalTest, TheFixtureItselfIsRefusedOnlyForItsDegreesOfFreedom) {
  const Fixture f;
  EXPECT_NO_THROW(io::LoadDataset(f.dir().string()));
  const FitcalRun r = RunFitcalOutside(
      f.root(), "fit --logs '" + f.dir().string() + "' --no-output --threads 1 --train-reps 1-2");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("2 training runs give 6 final-pose residuals for 9 free parameters"),
            std::string::npos)
      << r.err;
}

TEST(RefusalTest, NoRunMoves) {
  const Fixture f;
  for (int i = 1; i <= 3; ++i) f.Write("enc" + std::to_string(i) + ".csv", EncoderText(0, 2, 0));
  EXPECT_EQ(LoadKind(f), InputErrorKind::kNoMotion);
  ExpectFitRefused(f, "dataset.yaml: ", "no run moves");
}

TEST(RefusalTest, OneFileListedForTwoRunsIsADuplicate) {
  const Fixture f;
  f.Write("dataset.yaml",
          "robot: robot.yaml\nruns:\n"
          "  - {id: r1, trajectory: R1, repetition: 1, encoders: enc1.csv, ground_truth: gt1.csv}\n"
          "  - {id: r2, trajectory: R1, repetition: 2, encoders: ./enc1.csv, ground_truth: "
          "gt2.csv}\n");
  EXPECT_EQ(LoadKind(f), InputErrorKind::kDuplicateRun);
  ExpectFitRefused(f, "dataset.yaml:4: ", "a duplicated run");
}

TEST(RefusalTest, IdenticalContentUnderAnotherNameIsADuplicate) {
  const Fixture f;
  fs::copy_file(f.dir() / "enc1.csv", f.dir() / "enc3.csv", fs::copy_options::overwrite_existing);
  EXPECT_EQ(LoadKind(f), InputErrorKind::kDuplicateRun);
  ExpectFitRefused(f, "enc3.csv: ", "has the same encoder log as run 'r1'");
}

TEST(RefusalTest, ClockStepWhileTheWheelsTurn) {
  const Fixture f;
  // Row 101 (file line 103) jumps 60 s forward in the middle of the drive.
  std::string text = EncoderText(0.0, 1.0, 1.1);
  std::string tail = EncoderText(61.0, 1.0, 1.1);
  text += tail.substr(tail.find('\n') + 1);
  f.Write("enc2.csv", text);
  f.Write("gt2.csv", GroundTruthText(0.0, 62.0, 0.2));
  EXPECT_EQ(LoadKind(f), InputErrorKind::kClockGap);
  ExpectFitRefused(f, "enc2.csv:103: ", "the clock jumps 60 s");
}

TEST(RefusalTest, AGapAtRestIsAccepted) {
  const Fixture f;
  std::string text = EncoderText(0.0, 1.0, 1.1) + "1.020,0,0,0\n";  // stops
  std::string tail = EncoderText(61.02, 1.0, 0.0);                  // 60 s idle
  text += tail.substr(tail.find('\n') + 1);
  f.Write("enc2.csv", text);
  f.Write("gt2.csv", GroundTruthText(0.0, 62.0, 0.2));
  EXPECT_NO_THROW(io::LoadDataset(f.dir().string()));
}

TEST(RefusalTest, PhysicallyImpossibleRate) {
  const Fixture f;
  f.Write("enc1.csv", "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1,2,3\n0.02,1e300,2,3\n0.03,1,2,3\n");
  EXPECT_EQ(LoadKind(f), InputErrorKind::kImplausibleValue);
  ExpectFitRefused(f, "enc1.csv:4: ", "1e+300 rad/s is not a physical wheel rate");
}

TEST(RefusalTest, NanosecondTimestampsAreNamed) {
  const Fixture f;
  f.Write("gt1.csv", "t,x,y,theta\n1700000000000000000,0,0,0\n1700000000010000000,1,0,0\n");
  EXPECT_EQ(LoadKind(f), InputErrorKind::kImplausibleValue);
  ExpectFitRefused(f, "gt1.csv:2: ", "nanoseconds or microseconds instead of s");
}

// TUM rows: t x y z qx qy qz qw. A yaw of 0.3 rad about z.
std::string TumRow(double t, double x, double scale) {
  char row[160];
  std::snprintf(row, sizeof row, "%.3f %.4f 0 0 0 0 %.9f %.9f\n", t, x, scale * std::sin(0.15),
                scale * std::cos(0.15));
  return row;
}

TEST(RefusalTest, TumQuaternionNormalisedWithinToleranceWithAWarning) {
  const TempDir dir;
  const std::string path = dir.Write("gt.tum", TumRow(0, 0, 1.0005) + TumRow(1, 1, 1.0));
  std::vector<std::string> warnings;
  io::SetWarningSinkForTests([&](const std::string& w) { warnings.push_back(w); });
  const GroundTruthTrack track = io::ReadGroundTruth(path);
  io::SetWarningSinkForTests(nullptr);
  // The yaw of the normalised quaternion, not of the raw one (1 - 2 qz^2 assumes norm 1).
  // To the 9 decimals the file prints; the raw quaternion's yaw is 5e-4 rad off.
  EXPECT_NEAR(track.world_T_robot[0].theta, 0.3, 1e-8);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("gt.tum:1: 1 quaternion(s) normalised"), std::string::npos)
      << warnings[0];
}

TEST(RefusalTest, TumQuaternionBeyondToleranceIsRefused) {
  const Fixture f;
  std::string tum;
  for (int k = 0; k <= 20; ++k) tum += TumRow(0.1 * k, 0.05 * k, k == 5 ? 1.01 : 1.0);
  f.Write("gt1.csv", tum);
  EXPECT_EQ(LoadKind(f), InputErrorKind::kBadValue);
  ExpectFitRefused(f, "gt1.csv:6: ", "not a unit quaternion (norm 1.01");
}

TEST(RefusalTest, DuplicateKeysInAnyYaml) {
  {
    const Fixture f;
    std::string robot = ReadFileBytes(f.dir() / "robot.yaml");
    robot.insert(robot.find("name:"), "name: twice\n");
    f.Write("robot.yaml", robot);
    const FitcalRun r = RunFitcalOutside(f.root(), "fit --logs '" + f.dir().string() + "' --out '" +
                                                       f.out().string() + "' --train-reps 1-2");
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("robot.yaml:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("key 'name' appears twice"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(f.out()));
  }
  const Fixture f;
  f.Write("dataset.yaml",
          "robot: robot.yaml\nruns:\n"
          "  - {id: r1, trajectory: R1, repetition: 1, encoders: enc1.csv, ground_truth: gt1.csv,"
          " repetition: 2}\n");
  EXPECT_EQ(LoadKind(f), InputErrorKind::kDuplicateKey);
  ExpectFitRefused(f, "dataset.yaml:3: ", "key 'repetition' appears twice");
  // Nested maps too, anywhere in the document.
  const TempDir dir;
  const std::string path = dir.Write("x.yaml", "a:\n  - b: {c: 1, c: 2}\n");
  try {
    io::LoadYamlFile(path);
    ADD_FAILURE() << "accepted";
  } catch (const io::InputError& e) {
    EXPECT_EQ(e.kind(), InputErrorKind::kDuplicateKey) << e.what();
  }
}

TEST(RefusalTest, OutputThatIsAnInput) {
  const Fixture f;
  const std::string robot_before = ReadFileBytes(f.dir() / "robot.yaml");
  ExpectFitRefused(f, "robot.yaml: ", "is the input file", 2, (f.dir() / "robot.yaml").string());
  EXPECT_EQ(ReadFileBytes(f.dir() / "robot.yaml"), robot_before);
  // A directory output over the data set directory: refused, the data set untouched.
  const std::set<std::string> before = ListFiles(f.root());
  const FitcalRun r = RunFitcalOutside(
      f.root(), "report --logs '" + f.dir().string() + "' --calibration '" +
                    (f.dir() / "robot.yaml").string() + "' --out '" + f.dir().string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("ds: holds the input"), std::string::npos) << r.err;
  EXPECT_EQ(ListFiles(f.root()), before);
}

TEST(RefusalTest, SpecialFilesAreRefusedWithoutBlocking) {
  const Fixture f;
  fs::remove(f.dir() / "enc2.csv");
  ASSERT_EQ(::mkfifo((f.dir() / "enc2.csv").c_str(), 0644), 0);
  ExpectFitRefused(f, "enc2.csv: ", "is a FIFO (named pipe), not a regular file");
  fs::remove(f.dir() / "enc2.csv");
  fs::copy_file(f.dir() / "enc1.csv", f.dir() / "enc2.csv");
  // A character device as a log, and a FIFO as --out (writing would replace it).
  f.Write("dataset.yaml",
          "robot: robot.yaml\nruns:\n"
          "  - {id: r1, trajectory: R1, repetition: 1, encoders: /dev/zero, ground_truth: "
          "gt1.csv}\n");
  const FitcalRun dev =
      RunFitcalOutside(f.root(), "fit --logs '" + f.dir().string() +
                                     "' --allow-outside-paths --out '" + f.out().string() + "'");
  EXPECT_EQ(dev.exit_code, 1) << dev.err;
  EXPECT_NE(dev.err.find("/dev/zero: is a character device"), std::string::npos) << dev.err;
  const fs::path fifo_out = f.root() / "out.fifo";
  ASSERT_EQ(::mkfifo(fifo_out.c_str(), 0644), 0);
  const Fixture g;
  ExpectFitRefused(g, "out.fifo: ", "not a regular file", 2, fifo_out.string());
}

TEST(RefusalTest, ErrorLinesAreShortWhateverTheInputEchoes) {
  const Fixture f;
  f.Write("enc1.csv", "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1," + std::string(2 << 20, 'x') + ",3\n");
  ExpectFitRefused(f, "enc1.csv:3: ", "line longer than");
  f.Write("enc1.csv", "t,w_a,w_b,w_c\n0,0,0,0\n0.01,1," + std::string(500000, 'y') + ",3\n");
  ExpectFitRefused(f, "enc1.csv:3: ", "bytes]...");
  // A YAML key with a newline (and 1000 characters, YAML's limit for a key): one short line.
  f.Write("enc1.csv", EncoderText(0.0, 2.0, 1.1));
  const std::string valid = ReadFileBytes(f.dir() / "dataset.yaml");
  f.Write("dataset.yaml", "\"" + std::string(1000, 'k') + "\\nsecond line\": 1\n" + valid);
  ExpectFitRefused(f, "dataset.yaml:", "unknown key");
}

// The sanitizer build links the tests with AddressSanitizer's runtime but compiles the test objects
// as the Release build does (CMakeLists.txt), so the compiler's __SANITIZE_ADDRESS__ is not set:
// ask the runtime. __asan_init is its entry point, present only when it is linked in.
extern "C" void __asan_init() __attribute__((weak));
bool UnderAddressSanitizer() { return &__asan_init != nullptr; }

// Memory that runs out while a log is read is reported as such, with the file. The loader runs in
// a child process whose address space is capped 24 MB above what it already uses, so the samples
// of a 3.5-million-row log (140 MB) cannot be allocated (more than the 64 MB of freed heap glibc
// may keep mapped, which the cap cannot see, after the other tests).
TEST(RefusalTest, OutOfMemoryNamesTheFile) {
  // Under a memory limit AddressSanitizer's allocator aborts the process instead of throwing
  // std::bad_alloc, so the path under test cannot run there; the plain build runs it.
  if (UnderAddressSanitizer()) {
    GTEST_SKIP() << "AddressSanitizer aborts on allocation failure instead of throwing bad_alloc";
  }
  const Fixture f;
  std::string big = "t,w_a,w_b,w_c\n";
  big.reserve(48u << 20);
  char row[64];
  for (int k = 0; k < 3500000; ++k) {
    big.append(row, static_cast<std::size_t>(
                        std::snprintf(row, sizeof row, "%d.%02d,1,2,3\n", k / 100, k % 100)));
  }
  f.Write("enc1.csv", big);
  big.clear();
  big.shrink_to_fit();
  const fs::path report = f.root() / "child.txt";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    malloc_trim(0);
    std::ifstream statm("/proc/self/statm");
    unsigned long pages = 0;
    statm >> pages;
    const rlim_t cap =
        static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE)) + (24u << 20);
    const struct rlimit limit { cap, cap };
    setrlimit(RLIMIT_AS, &limit);
    std::string text = "accepted";
    try {
      io::LoadDataset(f.dir().string(), io::DatasetOptions{false, 1});
    } catch (const io::InputError& e) {
      text = std::string(e.kind() == io::InputErrorKind::kOutOfMemory ? "out of memory|"
                                                                   : "other input error|") +
             e.what();
    } catch (const std::exception& e) {
      text = std::string("other|") + e.what();
    }
    std::ofstream(report) << text;
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  const std::string text = ReadFileBytes(report);
  EXPECT_EQ(text.rfind("out of memory|", 0), 0u) << text;
  EXPECT_NE(text.find("enc1.csv: out of memory while reading this file"), std::string::npos)
      << text;
}

TEST(RefusalTest, UsageErrorsExitTwoInOneLine) {
  const Fixture f;
  for (const std::string& args : {"fit --logs '" + f.dir().string() + "' --train-reps 5-1",
                                  "fit --logs '" + f.dir().string() + "' --train-reps x",
                                  "diagnose --logs '" + f.dir().string() + "' --train-reps 3-1",
                                  "fit --logs '" + (f.root() / "missing").string() + "'",
                                  std::string("fit --no-such-flag")}) {
    SCOPED_TRACE(args);
    const std::set<std::string> before = ListFiles(f.root());
    const FitcalRun r = RunFitcalOutside(f.root(), args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("fitcal: ", 0), 0u) << r.err;
    EXPECT_EQ(ListFiles(f.root()), before);
  }
  EXPECT_NE(RunFitcalOutside(f.root(), "fit --logs '" + f.dir().string() + "' --train-reps 5-1")
                .err.find("range 5-1 is reversed"),
            std::string::npos);
}

// Ceres logs through glog, which writes to stderr before InitGoogleLogging: on rates of 1e150
// rad/s (once accepted) it printed "E... polynomial.cc:238] Failed to extract
// eigenvalues" and "W... residual_block.cc:129] Error in evaluating the ResidualBlock". Such rates
// are now refused, so FITCAL_TEST_LIBRARY_LOG makes fitcal write one glog line of every severity
// below FATAL where Ceres would; none may reach stderr, on an ill-posed fit either.
TEST(RefusalTest, NoLibraryLogLinesOnStderr) {
  const Fixture f;
  const std::regex glog_line("(^|\n)[IWEF][0-9]{4}");
  const FitcalRun r = RunFitcalOutside(
      f.root(), "fit --logs '" + f.dir().string() +
                    "' --no-output --threads 1 --train-reps 1-2 --skip-wheel-order-check");
  EXPECT_FALSE(std::regex_search(r.err, glog_line)) << r.err;
  EXPECT_EQ(r.err.find("InitGoogleLogging"), std::string::npos) << r.err;
  const FitcalRun hooked = RunFitcalOutside(
      f.root(), "fit --logs '" + f.dir().string() + "' --no-output --threads 1 --train-reps 1-2");
  ASSERT_EQ(setenv("FITCAL_TEST_LIBRARY_LOG", "1", 1), 0);
  const FitcalRun logged = RunFitcalOutside(
      f.root(), "fit --logs '" + f.dir().string() + "' --no-output --threads 1 --train-reps 1-2");
  unsetenv("FITCAL_TEST_LIBRARY_LOG");
  EXPECT_EQ(logged.exit_code, hooked.exit_code);
  EXPECT_FALSE(std::regex_search(logged.err, glog_line)) << logged.err;
  EXPECT_EQ(logged.err.find("test warning line"), std::string::npos) << logged.err;
  EXPECT_EQ(logged.err, hooked.err);
}

}  // namespace
}  // namespace fitcal
