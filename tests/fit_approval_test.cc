// Approval test of `fitcal fit` on the shipped flower (data/flower, omni3): the calibrated YAML's
// values as the fit wrote them before omni3's own fit path was retired (issue 30: one code path for
// every model). The arithmetic of the Ceres fit is the generic one (fit/model_fit.h) on both
// paths, so the values are compared as text, byte for byte: the 10 significant digits of the
// parameters and CFs, the sigmas, and M^-1 of Palacin Eq. 6 at 16 digits (the model's paper
// output). A change here is a change of the numbers a user gets; say why in the commit.

#include <gtest/gtest.h>

#include <string>

#include "models/model_registry.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

using fitcal::testing::ReadFileBytes;
using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;

const std::string kFlower = std::string(FITCAL_SOURCE_DIR) + "/data/flower";

// Recorded at main a0be7a1 (`fitcal fit --logs data/flower --out ...`, omni3's own path).
constexpr const char* kFlowerCeresLines[] = {
    "  - {name: a, distance_m: 0.2182155469, radius_m: 0.1551166988, angle_deg: 59.7764792}",
    "  - {name: b, distance_m: 0.2158641842, radius_m: 0.1515536071, angle_deg: 179.7229843}",
    "  - {name: c, distance_m: 0.2157896058, radius_m: 0.1527965891, angle_deg: 301.6264867}",
    "  method: ceres",
    "  termination: CONVERGENCE",
    "  at_bound: []",
    "  cf_training: {before: 0.0727613984, after: 0.007619401906}",
    "  cf_validation: {before: 0.07260223942, after: 0.007842772719}",
    // The sigmas of omni3's own path, in the calibration block every model writes (one key per
    // parameter with its unit; omni3's path grouped them as distance_m/radius_m/angle_deg
    // triples): the same digits.
    "    R_a_m: 0.0005307746265",
    "    R_b_m: 0.0005342887409",
    "    R_c_m: 0.0005318928477",
    "    r_a_m: 8.174740739e-05",
    "    r_b_m: 8.231970382e-05",
    "    r_c_m: 8.19659072e-05",
    "    delta_a_deg: 0.03113920202",
    "    delta_b_deg: 0.03018882245",
    "    delta_c_deg: 0.03058191495",
    "  inverse_kinematic_matrix:",
    "    - [-0.0907109481143395, 0.001563791926711912, 0.08878153875422096]",
    "    - [0.05096867034743491, -0.1002874686141022, 0.0503741807584078]",
    "    - [0.2340800722689612, 0.2375330187314411, 0.2353462880553444]",
};

TEST(FitApproval, FlowerCeresFitWritesTheRecordedCalibration) {
  TempDir dir;
  const std::string out = dir.Path("calibrated.yaml");
  const auto r = RunFitcal(dir, "fit --logs " + kFlower + " --out " + out);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::string yaml = ReadFileBytes(out);
  for (const char* line : kFlowerCeresLines) {
    EXPECT_NE(yaml.find(std::string(line) + "\n"), std::string::npos) << line << "\n" << yaml;
  }
  // The printed held-out CF is the recorded one, at the table's 4 decimals.
  EXPECT_NE(r.out.find("validation                         0.0726     0.0078    -89.2%"),
            std::string::npos)
      << r.out;
}

// The YAML reader keeps the omni3 layout: the shipped robot, and a calibration written by omni3's
// own fit path (sigma triples per group, main a0be7a1) whose block is informational when read.
TEST(FitApproval, TheOmni3LayoutsStillLoad) {
  const RobotModelPtr shipped = ReadRobotModelFile(kFlower + "/robot.yaml");
  EXPECT_EQ(shipped->robot().model, "omni3");
  EXPECT_EQ(shipped->robot().nominal[0], 0.195);
  TempDir dir;
  dir.Write("old.yaml", R"(model: omni3
name: apr02
wheels:
  - {name: a, distance_m: 0.2182155469, radius_m: 0.1551166988, angle_deg: 59.7764792}
  - {name: b, distance_m: 0.2158641842, radius_m: 0.1515536071, angle_deg: 179.7229843}
  - {name: c, distance_m: 0.2157896058, radius_m: 0.1527965891, angle_deg: 301.6264867}
bounds:
  distance_m: [0.17, 0.22]
  radius_m: [0.138, 0.158]
  angle_offset_deg: [-2, 2]
calibration:
  method: ceres
  training_repetitions: [1, 2, 3, 4, 5]
  at_bound: []
  cf_validation: {before: 0.07260223942, after: 0.007842772719}
  sigma:
    distance_m: [0.0005307746265, 0.0005342887409, 0.0005318928477]
    radius_m: [8.174740739e-05, 8.231970382e-05, 8.19659072e-05]
    angle_deg: [0.03113920202, 0.03018882245, 0.03058191495]
  inverse_kinematic_matrix:
    - [-0.0907109481143395, 0.001563791926711912, 0.08878153875422096]
    - [0.05096867034743491, -0.1002874686141022, 0.0503741807584078]
    - [0.2340800722689612, 0.2375330187314411, 0.2353462880553444]
)");
  const RobotModelPtr old = ReadRobotModelFile(dir.Path("old.yaml"));
  EXPECT_EQ(old->robot().nominal[0], 0.2182155469);
  EXPECT_EQ(old->robot().nominal[5], 0.1527965891);
}

}  // namespace
}  // namespace fitcal
