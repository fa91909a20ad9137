// Issue 43 item 3: the hidden corpora's defects, one class per test, each through the command
// line as a user meets it, each checked against a value the test computes itself (a file name
// from the documented mapping, a pose from the input file, a YAML string as written):
//   - data that cannot teach, said in words (runs that stand still; ground truth of start and end
//     poses only, which is not a unit error);
//   - flags that do not apply refused (exit 2) or stated;
//   - edited calibration blocks and fleet inputs validated (duplicates, bounds, versions, models);
//   - one file per run on disk (report --tum);
//   - YAML writers that quote every user string;
//   - export --logs with nothing held out refused, as report refuses it.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/dataset_edit.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;
using testing::FitcalRun;
using testing::Has;
using testing::Lines;
using testing::ReadFileBytes;
using testing::RunFitcal;
using testing::TempDir;
using testing::WriteFileBytes;

using testing::Csv;
using testing::ReadCsv;
using testing::RunFiles;
using testing::Runs;
using testing::Shell;
using testing::SimulateDiffDrive;
using testing::WriteCsv;

// ---------------------------------------------------------------------------------------------
// Data that cannot teach, said in words.

// Training runs that stand still (wheels at rest, the ground truth where it started, with a
// motion capture's millimetre of noise) determine nothing: refused in one line naming why, exit 1
// (bad input), nothing written. The held-out runs move, so the data set itself loads.
TEST(CorpusClasses, TrainingRunsThatStandStillAreRefusedInWords) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data");
  double phase = 0.0;  // each run its own noise: identical files would be refused as copies
  for (const RunFiles& run : Runs(data)) {
    if (run.repetition != 1) continue;
    phase += 1.0;
    Csv encoders = ReadCsv(run.encoders);
    for (std::size_t k = 0; k < encoders.rows.size(); ++k) {
      for (std::size_t c = 1; c < encoders.rows[k].size(); ++c) {
        encoders.rows[k][c] = 1e-4 * std::sin(1.3 * static_cast<double>(k + c) + phase);
      }
    }
    WriteCsv(run.encoders, encoders);
    Csv truth = ReadCsv(run.ground_truth);
    for (std::size_t k = 0; k < truth.rows.size(); ++k) {
      const double noise_m = 0.001 * std::sin(1.7 * static_cast<double>(k) + phase);
      truth.rows[k] = {truth.rows[k][0], 1.0 + noise_m, 2.0 - noise_m, 0.3 + noise_m};
    }
    WriteCsv(run.ground_truth, truth);
  }
  const std::string out = dir.Path("cal.yaml");
  const FitcalRun r = RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + out);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "stand still")) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// Ground truth holding only each run's start and end poses (runs cut at 90 % of a loop, so that
// the straight line between the ends is far shorter than the path): the path is not measured, so
// it is no evidence of a unit error; the fit takes the final poses and writes its calibration.
TEST(CorpusClasses, GroundTruthOfStartAndEndOnlyIsFittedOnFinalPoses) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data");
  for (const RunFiles& run : Runs(data)) {
    Csv truth = ReadCsv(run.ground_truth);
    const std::size_t cut = truth.rows.size() * 9 / 10;
    const double t_end = truth.rows[cut][0];
    truth.rows = {truth.rows.front(), truth.rows[cut]};
    WriteCsv(run.ground_truth, truth);
    Csv encoders = ReadCsv(run.encoders);
    while (encoders.rows.size() > 2 && encoders.rows.back()[0] > t_end) encoders.rows.pop_back();
    WriteCsv(run.encoders, encoders);
  }
  const std::string out = dir.Path("cal.yaml");
  const FitcalRun r = RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + out);
  EXPECT_FALSE(Has(r.err, "rad/s")) << r.err;
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(Has(r.out, "residuals: final-pose")) << r.out;
  EXPECT_TRUE(fs::exists(out));
}

// ---------------------------------------------------------------------------------------------
// Flags that do not apply: refused (exit 2, one line, before anything is read) when the flags
// alone say so, stated when --residuals auto's choice leaves them unused.

TEST(CorpusClasses, FlagsThatDoNotApplyAreRefused) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data", 1);
  const std::string out = dir.Path("cal.yaml");
  struct Case {
    std::string flags, named;
  };
  for (const Case& c : std::vector<Case>{
           {"--residuals track --loss huber", "--loss"},
           {"--residuals track --objective eq14", "--objective"},
           {"--residuals final-pose --clock-offsets session", "--clock-offsets"},
           {"--method crs2lm --loss cauchy", "--loss"},
           {"--method crs2lm --max-iterations 5", "--max-iterations"},
           {"--seed 7", "--seed"},
           {"--polish", "--polish"},
           {"--loss-scale 0.1", "--loss-scale"},
       }) {
    SCOPED_TRACE(c.flags);
    const FitcalRun r =
        RunFitcal(dir, "fit --logs " + data + " --train-reps 1 " + c.flags + " --out " + out);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_TRUE(Has(r.err, c.named)) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

// The default track fit (dense ground truth) and --loss: the track residual has its own fixed
// Huber loss, so --loss is said to be unused; the same for --clock-offsets when auto takes the
// final poses (ground truth of start and end only).
TEST(CorpusClasses, FlagsTheResidualChoiceLeavesUnusedAreStated) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data");
  const FitcalRun track =
      RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --loss huber --no-output");
  EXPECT_EQ(track.exit_code, 0) << track.out << track.err;
  EXPECT_TRUE(Has(track.out, "residuals: track (--residuals auto)")) << track.out;
  EXPECT_TRUE(Has(track.out, "note: --loss huber not applied")) << track.out;
  for (const RunFiles& run : Runs(data)) {
    Csv truth = ReadCsv(run.ground_truth);
    truth.rows = {truth.rows.front(), truth.rows.back()};
    WriteCsv(run.ground_truth, truth);
  }
  const FitcalRun final_pose =
      RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --clock-offsets session --no-output");
  EXPECT_TRUE(Has(final_pose.out, "residuals: final-pose (--residuals auto)")) << final_pose.out;
  EXPECT_TRUE(Has(final_pose.out, "note: --clock-offsets session not applied")) << final_pose.out;
}

// ---------------------------------------------------------------------------------------------
// Edited calibration blocks and fleet inputs validated.

// A calibration whose block lists clock offsets as `groups_text` (after `clock_offsets:`), and the
// 1-based line of the text's `marker` in the file.
std::pair<std::string, int> WithClockOffsets(const TempDir& dir, const std::string& calibration,
                                             const std::string& groups_text,
                                             const std::string& marker) {
  std::string text = ReadFileBytes(calibration);
  const std::size_t at = text.find("calibration:\n");
  EXPECT_NE(at, std::string::npos);
  text.insert(at + 13, "  clock_offsets:\n    grouping: session\n    groups:\n" + groups_text);
  const std::string path = dir.Write("edited.yaml", text);
  const std::size_t mark = text.find(marker);
  return {path, 1 + static_cast<int>(std::count(text.begin(), text.begin() + mark, '\n'))};
}

TEST(CorpusClasses, EditedClockOffsetsAreValidatedWithFileAndLine) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data");
  const std::string cal = dir.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + cal).exit_code, 0);
  struct Case {
    std::string groups, marker, says;
  };
  for (const Case& c : std::vector<Case>{
           {"      - {group: S1, offset_s: 0.01, sigma_s: 0.001}\n"
            "      - {group: S1, offset_s: 0.02, sigma_s: 0.001}\n",
            "offset_s: 0.02", "listed twice"},
           {"      - {group: S1, offset_s: 0.75, sigma_s: 0.001}\n", "offset_s: 0.75",
            "beyond the fit's bound"},
       }) {
    SCOPED_TRACE(c.says);
    const auto [edited, line] = WithClockOffsets(dir, cal, c.groups, c.marker);
    const std::string rep = dir.Path("rep");
    const FitcalRun r =
        RunFitcal(dir, "report --logs " + data + " --calibration " + edited + " --out " + rep);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_TRUE(Has(r.err, edited + ":" + std::to_string(line) + ":")) << r.err << line;
    EXPECT_TRUE(Has(r.err, c.says)) << r.err;
    EXPECT_FALSE(fs::exists(rep));
  }
}

const char* kDiffYaml = R"(model: diff_drive
name: r1
wheels:
  - {name: right, radius_m: 0.042}
  - {name: left, radius_m: 0.042}
wheel_separation_m: 0.200
bounds: {radius_m: [0.030, 0.050], wheel_separation_m: [0.180, 0.220]}
calibration:
  training_repetitions: [1]
)";

// fleet: a metrics.json of a version this fitcal does not know is refused (its parameters may have
// moved: reading it would drop them), and two robots of one name and different models are not
// merged into one series.
TEST(CorpusClasses, FleetRefusesUnknownVersionsAndOneNameForTwoModels) {
  const TempDir dir;
  const std::string yaml = dir.Write("fleet/r1/2026-05-01/cal.yaml", kDiffYaml);
  const std::string json = R"({"version": VERSION, "robot": "r1", "parameters": [
      {"name": "r_left", "calibrated_m": 0.0412}]})";
  const auto metrics = [&](const std::string& version) {
    std::string text = json;
    text.replace(text.find("VERSION"), 7, version);
    return dir.Write("fleet/r1/2026-05-08/report/metrics.json", text);
  };
  metrics("2");
  const FitcalRun known = RunFitcal(dir, "fleet " + dir.Path("fleet"));
  EXPECT_EQ(known.exit_code, 0) << known.err;
  const std::string unknown = metrics("3");
  const FitcalRun refused = RunFitcal(dir, "fleet " + dir.Path("fleet"));
  EXPECT_EQ(refused.exit_code, 1) << refused.out << refused.err;
  EXPECT_EQ(Lines(refused.err), 1) << refused.err;
  EXPECT_TRUE(Has(refused.err, unknown + ":1:")) << refused.err;
  EXPECT_TRUE(Has(refused.err, "version 3")) << refused.err;
  fs::remove(unknown);

  std::string omni3 = ReadFileBytes(std::string(FITCAL_SOURCE_DIR) + "/data/robots/apr02.yaml");
  omni3.replace(omni3.find("name: apr02"), 11, "name: r1");
  const std::string other = dir.Write("fleet/r1/2026-05-15/cal.yaml",
                                      omni3 + "calibration:\n  training_repetitions: [1]\n");
  const FitcalRun merged = RunFitcal(dir, "fleet " + yaml + " " + other);
  EXPECT_EQ(merged.exit_code, 1) << merged.out << merged.err;
  EXPECT_EQ(Lines(merged.err), 1) << merged.err;
  EXPECT_TRUE(Has(merged.err, "robot 'r1' is a omni3 here and a diff_drive")) << merged.err;
}

// ---------------------------------------------------------------------------------------------
// One file per run on disk.

// The documented mapping (docs/tum.md), computed here independently: bytes outside
// [A-Za-z0-9._-] and a leading '.' as %XX.
std::string TumStem(const std::string& id) {
  std::string out;
  for (std::size_t i = 0; i < id.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(id[i]);
    if (std::isalnum(c) || c == '_' || c == '-' || (c == '.' && i > 0)) {
      out += static_cast<char>(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

// Held-out runs named "loop/1", "loop_1" and ".loop" (one file each, none hidden), each file
// holding its own run's ground truth: its first pose is the input's row at that time.
TEST(CorpusClasses, TumFilesAreOnePerRunWhateverTheIds) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data");
  ASSERT_EQ(
      RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + dir.Path("cal.yaml"))
          .exit_code,
      0);
  std::string index = ReadFileBytes(data + "/dataset.yaml");
  std::vector<RunFiles> held_out;
  const std::vector<std::string> ids = {"loop/1", "loop_1", ".loop"};
  for (const RunFiles& run : Runs(data)) {
    if (run.repetition != 2 || held_out.size() == ids.size()) continue;
    const std::string from = "id: " + run.id + ",";
    index.replace(index.find(from), from.size(), "id: \"" + ids[held_out.size()] + "\",");
    held_out.push_back(run);
  }
  WriteFileBytes(data + "/dataset.yaml", index);
  const std::string rep = dir.Path("rep");
  const FitcalRun r = RunFitcal(dir, "report --logs " + data + " --calibration " +
                                         dir.Path("cal.yaml") + " --out " + rep + " --tum");
  ASSERT_TRUE(r.exit_code == 0 || r.exit_code >= 7) << r.out << r.err;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    SCOPED_TRACE(ids[k]);
    const std::string tum = rep + "/tum/" + TumStem(ids[k]) + ".ground_truth.tum";
    ASSERT_TRUE(fs::exists(tum)) << tum;
    std::istringstream in(ReadFileBytes(tum));
    std::string line;
    std::getline(in, line);  // the header comment
    std::getline(in, line);
    double t = 0, x = 0, y = 0;
    std::istringstream(line) >> t >> x >> y;
    bool found = false;
    for (const auto& row : ReadCsv(held_out[k].ground_truth).rows) {
      if (std::abs(row[0] - t) > 1e-9) continue;
      found = true;
      EXPECT_NEAR(row[1], x, 1e-12);
      EXPECT_NEAR(row[2], y, 1e-12);
    }
    EXPECT_TRUE(found) << "the first pose is no sample of the run's ground truth";
  }
}

// ---------------------------------------------------------------------------------------------
// YAML writers quote every user string.

// Joint and node names with a quote, `: #`, a leading '-', a backslash and unicode: the exported
// YAML parses, and yaml-cpp reads every name back as written.
TEST(CorpusClasses, ExportedYamlKeepsEveryNameAsWritten) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data");
  const std::string cal = dir.Path("cal.yaml");
  ASSERT_EQ(RunFitcal(dir, "fit --logs " + data + " --train-reps 1 --out " + cal).exit_code, 0);
  const std::vector<std::array<std::string, 3>> cases = {
      {"base: #1", "r\"ight", "-left: #x"},
      {"- node", "back\\slash", "r\xC3\xA4" "d_\xE2\x9C\x93"},
      {"\"quoted\"", "'single'", "tab\there"},
  };
  for (const auto& [node, right, left] : cases) {
    SCOPED_TRACE(node);
    const std::string out = dir.Path("params.yaml");
    const FitcalRun r = RunFitcal(
        dir, "export ros2-control --controller diff_drive_controller --calibration " + cal +
                 " --node-name " + Shell(node) + " --joints " + Shell(right + "," + left) +
                 " --out " + out + " --force");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    YAML::Node root;
    ASSERT_NO_THROW(root = YAML::LoadFile(out)) << ReadFileBytes(out);
    ASSERT_TRUE(root[node]) << ReadFileBytes(out);
    const YAML::Node p = root[node]["ros__parameters"];
    EXPECT_EQ(p["right_wheel_names"][0].as<std::string>(), right) << ReadFileBytes(out);
    EXPECT_EQ(p["left_wheel_names"][0].as<std::string>(), left) << ReadFileBytes(out);
  }
}

// ---------------------------------------------------------------------------------------------
// export --logs on a data set the calibration trained on entirely: refused as report refuses it
// (exit 2, one line), nothing written - not a covariance "from N held-out runs".
TEST(CorpusClasses, ExportWithNothingHeldOutIsRefusedAsReportRefusesIt) {
  const TempDir dir;
  const std::string data = SimulateDiffDrive(dir, "data", 1);
  const std::string cal = dir.Path("cal.yaml");
  const FitcalRun fit = RunFitcal(dir, "fit --logs " + data + " --out " + cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const FitcalRun report =
      RunFitcal(dir, "report --logs " + data + " --calibration " + cal + " --out " + dir.Path("r"));
  EXPECT_EQ(report.exit_code, 2) << report.err;
  const std::string out = dir.Path("params.yaml");
  const FitcalRun r =
      RunFitcal(dir, "export ros2-control --controller diff_drive_controller --calibration " + cal +
                         " --logs " + data + " --out " + out);
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_TRUE(Has(r.err, "trained the calibration")) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace fitcal
