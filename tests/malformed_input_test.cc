// The malformed-input corpus (tests/malformed/): every file is one thing a recorder or a hand
// edit gets wrong. Each case is placed into an otherwise valid data set in the role its prefix
// names (enc_ -> the encoder CSV, gt_ -> the ground truth, robot_ -> the robot YAML, dataset_ ->
// dataset.yaml) and must
//   1. make the loaders throw InputError of exactly the listed kind, naming the file and line;
//   2. make the fitcal CLI exit non-zero with one line on stderr naming file:line, writing no
//      output file and leaving no temporary file behind.
// ok_* files (Windows line endings, UTF-8 byte-order mark) must load.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include "io/dataset.h"
#include "io/input_error.h"
#include "io/text_file.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/test_files.h"
#include "tests/omni3_robot.h"
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

struct MalformedCase {
  const char* file;        // in tests/malformed/
  InputErrorKind kind;     // exact kind the loaders must report
  const char* error_file;  // the error must name a path ending in this
  int line;                // and this line (0 = the file as a whole)
};

// clang-format off
const MalformedCase kCases[] = {
    {"enc_empty.csv",                   InputErrorKind::kEmptyFile,         "enc.csv", 1},
    {"enc_blank_lines_only.csv",        InputErrorKind::kEmptyFile,         "enc.csv", 1},
    {"enc_header_only.csv",             InputErrorKind::kTooFewSamples,     "enc.csv", 0},
    {"enc_one_row.csv",                 InputErrorKind::kTooFewSamples,     "enc.csv", 0},
    {"enc_wrong_header.csv",            InputErrorKind::kBadHeader,         "enc.csv", 1},
    {"enc_header_extra_column.csv",     InputErrorKind::kBadHeader,         "enc.csv", 1},
    {"enc_semicolons.csv",              InputErrorKind::kBadHeader,         "enc.csv", 1},
    {"enc_asoc_file_for_omni3.csv",     InputErrorKind::kBadHeader,         "enc.csv", 1},
    {"enc_missing_column.csv",          InputErrorKind::kWrongColumnCount,  "enc.csv", 3},
    {"enc_extra_column.csv",            InputErrorKind::kWrongColumnCount,  "enc.csv", 4},
    {"enc_non_numeric.csv",             InputErrorKind::kNonNumeric,        "enc.csv", 3},
    {"enc_empty_field.csv",             InputErrorKind::kNonNumeric,        "enc.csv", 3},
    {"enc_nan.csv",                     InputErrorKind::kNonFinite,         "enc.csv", 4},
    {"enc_inf.csv",                     InputErrorKind::kNonFinite,         "enc.csv", 3},
    {"enc_huge_number.csv",             InputErrorKind::kNonFinite,         "enc.csv", 3},
    {"enc_duplicate_time.csv",          InputErrorKind::kNonIncreasingTime, "enc.csv", 4},
    {"enc_decreasing_time.csv",         InputErrorKind::kNonIncreasingTime, "enc.csv", 4},
    {"gt_empty.csv",                    InputErrorKind::kEmptyFile,         "gt.csv", 1},
    {"gt_header_only.csv",              InputErrorKind::kTooFewSamples,     "gt.csv", 0},
    {"gt_wrong_header.csv",             InputErrorKind::kBadHeader,         "gt.csv", 1},
    {"gt_missing_column.csv",           InputErrorKind::kWrongColumnCount,  "gt.csv", 3},
    {"gt_nan.csv",                      InputErrorKind::kNonFinite,         "gt.csv", 3},
    {"gt_decreasing_time.csv",          InputErrorKind::kNonIncreasingTime, "gt.csv", 3},
    {"gt_outside_encoder_span.csv",     InputErrorKind::kNoOverlap,         "gt.csv", 0},
    {"gt_tum_bad_quaternion.csv",       InputErrorKind::kBadValue,          "gt.csv", 2},
    {"gt_tum_missing_column.csv",       InputErrorKind::kWrongColumnCount,  "gt.csv", 3},
    {"robot_bounds_lo_gt_hi.yaml",      InputErrorKind::kBadValue,          "robot.yaml", 11},
    {"robot_start_outside_bounds.yaml", InputErrorKind::kBadValue,          "robot.yaml", 7},
    {"robot_negative_radius.yaml",      InputErrorKind::kBadValue,          "robot.yaml", 8},
    {"robot_two_wheels.yaml",           InputErrorKind::kBadValue,          "robot.yaml", 6},
    // Misspelt, named on its own line (issue 31), not reported as radius_m missing from bounds.
    {"robot_unknown_key.yaml",          InputErrorKind::kUnknownKey,        "robot.yaml", 11},
    {"robot_missing_bounds.yaml",       InputErrorKind::kMissingKey,        "robot.yaml", 3},
    {"robot_yaml_syntax.yaml",          InputErrorKind::kYamlSyntax,        "robot.yaml", 8},
    {"robot_unknown_model.yaml",        InputErrorKind::kUnknownModel,      "robot.yaml", 3},
    {"robot_wheel_not_a_map.yaml",      InputErrorKind::kWrongYamlType,     "robot.yaml", 6},
    {"robot_effect_needs_steering.yaml", InputErrorKind::kBadValue,         "robot.yaml", 15},
    {"dataset_dotdot_escape.yaml",      InputErrorKind::kBadPath,           "dataset.yaml", 3},
    {"dataset_absolute_path.yaml",      InputErrorKind::kBadPath,           "dataset.yaml", 3},
    {"dataset_robot_outside.yaml",      InputErrorKind::kBadPath,           "dataset.yaml", 1},
    {"dataset_missing_robot_file.yaml", InputErrorKind::kMissingFile,       "dataset.yaml", 1},
    {"dataset_robot_path_too_long.yaml", InputErrorKind::kMissingFile,      "dataset.yaml", 1},
    {"dataset_missing_encoder_file.yaml", InputErrorKind::kMissingFile,     "enc_missing.csv", 0},
    {"dataset_encoder_is_directory.yaml", InputErrorKind::kMissingFile,     "/.", 0},
    {"dataset_duplicate_run_id.yaml",   InputErrorKind::kDuplicateRunId,    "dataset.yaml", 4},
    {"dataset_no_runs.yaml",            InputErrorKind::kTooFewSamples,     "dataset.yaml", 2},
    {"dataset_runs_not_a_list.yaml",    InputErrorKind::kWrongYamlType,     "dataset.yaml", 2},
    {"dataset_unknown_key.yaml",        InputErrorKind::kUnknownKey,        "dataset.yaml", 2},
    {"dataset_missing_key.yaml",        InputErrorKind::kMissingKey,        "dataset.yaml", 3},
    {"dataset_repetition_not_whole.yaml", InputErrorKind::kBadValue,        "dataset.yaml", 3},
    {"dataset_start_pose_two_values.yaml", InputErrorKind::kBadValue,       "dataset.yaml", 3},
    {"dataset_yaml_syntax.yaml",        InputErrorKind::kYamlSyntax,        "dataset.yaml", 4},
};
// clang-format on

const fs::path kCorpus = fs::path(FITCAL_SOURCE_DIR) / "tests" / "malformed";

// Which file of the data set a case replaces, from its prefix.
std::string RoleFile(const std::string& case_file) {
  const std::string name = case_file.rfind("ok_", 0) == 0 ? case_file.substr(3) : case_file;
  if (name.rfind("enc_", 0) == 0) return "enc.csv";
  if (name.rfind("gt_", 0) == 0) return "gt.csv";
  if (name.rfind("robot_", 0) == 0) return "robot.yaml";
  if (name.rfind("dataset_", 0) == 0) return "dataset.yaml";
  return "";
}

// A valid one-run data set in <root>/ds, with `case_file` in place of its role's file.
class DatasetDir {
 public:
  explicit DatasetDir(const std::string& case_file) : dir_(temp_.path() / "ds") {
    fs::create_directories(dir_);
    fs::copy_file(fs::path(FITCAL_SOURCE_DIR) / "data" / "robots" / "apr02.yaml",
                  dir_ / "robot.yaml");
    WriteFileBytes(dir_ / "dataset.yaml",
                   "robot: robot.yaml\nruns:\n  - {id: r1, trajectory: R1, repetition: 1, "
                   "encoders: enc.csv, ground_truth: gt.csv}\n");
    WriteFileBytes(dir_ / "enc.csv", "t,w_a,w_b,w_c\n0.00,0,0,0\n0.01,1,2,3\n0.02,1,2,3\n");
    WriteFileBytes(dir_ / "gt.csv", "t,x,y,theta\n0,0,0,0\n0.02,0.001,0,0\n");
    if (!case_file.empty()) {
      fs::copy_file(kCorpus / case_file, dir_ / RoleFile(case_file),
                    fs::copy_options::overwrite_existing);
    }
  }
  const fs::path& root() const { return temp_.path(); }
  const fs::path& dir() const { return dir_; }

 private:
  TempDir temp_;  // declared first: dir_ lives inside it
  fs::path dir_;
};

// What `fitcal fit` loads before it fits (the registry's reader, through omni3's named view).
void LoadForFit(const fs::path& dir, const io::DatasetOptions& options = {}) {
  const io::Dataset dataset = io::LoadDataset(dir.string(), options);
  ReadOmni3Robot(dataset.robot_path);
}

TEST(MalformedInputTest, CorpusHasAtLeastThirtyCasesAndEveryFileIsListed) {
  std::set<std::string> listed;
  for (const MalformedCase& c : kCases) listed.insert(c.file);
  EXPECT_GE(listed.size(), 30u);
  EXPECT_EQ(listed.size(), std::size(kCases)) << "a case is listed twice";
  for (const auto& entry : fs::directory_iterator(kCorpus)) {
    const std::string name = entry.path().filename().string();
    EXPECT_FALSE(RoleFile(name).empty()) << name << " has no role prefix";
    if (name.rfind("ok_", 0) != 0) {
      EXPECT_TRUE(listed.count(name)) << name << " is not in kCases";
    }
  }
}

TEST(MalformedInputTest, LoadersReportTheExactErrorKindFileAndLine) {
  for (const MalformedCase& c : kCases) {
    SCOPED_TRACE(c.file);
    const DatasetDir data(c.file);
    try {
      LoadForFit(data.dir());
      ADD_FAILURE() << "accepted";
    } catch (const io::InputError& e) {
      EXPECT_EQ(e.kind(), c.kind) << e.what();
      const std::string suffix = c.error_file;
      EXPECT_TRUE(e.file().size() >= suffix.size() &&
                  e.file().compare(e.file().size() - suffix.size(), suffix.size(), suffix) == 0)
          << e.what();
      EXPECT_EQ(e.line(), c.line) << e.what();
    }
  }
}

TEST(MalformedInputTest, CliPrintsOneLineExitsNonZeroAndWritesNothing) {
  for (const MalformedCase& c : kCases) {
    SCOPED_TRACE(c.file);
    const DatasetDir data(c.file);
    const fs::path out = data.root() / "calibrated.yaml";
    const std::set<std::string> before = ListFiles(data.root());
    const FitcalRun r =
        RunFitcalOutside(data.root(), "--logs '" + data.dir().string() + "' --out '" +
                                          out.string() + "' --threads 1");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    // The CLI checks the model before it parses the rest of the robot (fit_command.cc), so it
    // names the file only for an unknown model.
    const int line = c.kind == InputErrorKind::kUnknownModel ? 0 : c.line;
    const std::string where =
        std::string(c.error_file) + (line > 0 ? ":" + std::to_string(line) + ":" : ":");
    EXPECT_NE(r.err.find(where), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(ListFiles(data.root()), before) << "a file was created";
  }
}

TEST(MalformedInputTest, WindowsLineEndingsAndByteOrderMarkAreAccepted) {
  for (const char* file : {"ok_enc_bom_crlf.csv", "ok_gt_bom_crlf.csv", "ok_robot_bom_crlf.yaml",
                           "ok_dataset_bom_crlf.yaml"}) {
    SCOPED_TRACE(file);
    const DatasetDir data(file);
    EXPECT_NO_THROW(LoadForFit(data.dir()));
  }
  const DatasetDir data("ok_enc_bom_crlf.csv");
  const io::Dataset dataset = io::LoadDataset(data.dir().string());
  ASSERT_EQ(dataset.runs[0].encoders.samples.size(), 2u);
  EXPECT_DOUBLE_EQ(dataset.runs[0].encoders.samples[1].value[2], 3.0);
}

TEST(MalformedInputTest, OutsidePathsLoadOnlyWithTheFlag) {
  const DatasetDir data("dataset_dotdot_escape.yaml");
  fs::copy_file(data.dir() / "enc.csv", data.root() / "enc.csv");
  EXPECT_THROW(LoadForFit(data.dir()), io::InputError);
  io::DatasetOptions options;
  options.allow_paths_outside = true;
  EXPECT_NO_THROW(LoadForFit(data.dir(), options));
}

// A file larger than the memory fitcal may use is refused before anything is allocated. A
// sparse file of 1 TiB takes no disk space.
TEST(MalformedInputTest, FileLargerThanMemoryIsRefusedWithAMessage) {
  const DatasetDir data("");
  const fs::path big = data.dir() / "enc.csv";
  fs::resize_file(big, std::uintmax_t{1} << 40);
  try {
    io::ReadTextFile(big.string());
    ADD_FAILURE() << "a 1 TiB file was accepted";
  } catch (const io::InputError& e) {
    EXPECT_EQ(e.kind(), InputErrorKind::kTooLarge);
    EXPECT_NE(std::string(e.what()).find("free memory"), std::string::npos) << e.what();
  }
  const fs::path out = data.root() / "calibrated.yaml";
  const FitcalRun r = RunFitcalOutside(
      data.root(), "--logs '" + data.dir().string() + "' --out '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("enc.csv: file of 1099511627776 bytes"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace fitcal
