// diagnose from a guess far off: a differential drive whose left wheel is 23 % smaller than its
// robot YAML says (stop 67's diagnose sweep, diff_drive_003, here without its truncated runs).
// The declared final-pose fit stops in a minimum of the final poses, and the track fit started
// from it stayed there: before, diagnose wrote a calibration with held-out CF 2.76 against the
// nominal's 2.84 (its track fit ended on every bound). The track fit from the fit of 0.5 m
// windows (diagnosis/diagnose.cc FitBase) now competes: it must be selected, and the written radii
// and separation must lie within 3 of their written sigmas of the simulated truth (they do within
// 0.35). With the fix undone it fails: the declared fit is selected. fitcal's own simulator,
// judged against the truth it was given.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>

#include "models/model_registry.h"
#include "tests/test_files.h"
#include "tests/written_calibration_checks.h"

namespace diagnose_far_guess_cli_test {  // named, not anonymous: tests compile in batches

using fitcal::testing::Has;
using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;
using fitcal::testing::WriteFileBytes;

constexpr const char* kBounds = "bounds: {radius_m: [0.025, 0.060], wheel_separation_m: [0.120, "
                                "0.300]}\n";

TEST(DiagnoseFarGuess, ATrackFitFromTheWindowsFindsTheTruth) {
  TempDir dir;
  WriteFileBytes(dir.Path("nominal.yaml"),
                 std::string("model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: "
                             "0.042}\n  - {name: left, radius_m: 0.042}\nwheel_separation_m: "
                             "0.200\n") + kBounds);
  WriteFileBytes(dir.Path("truth.yaml"),
                 std::string("model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: "
                             "0.0459649202}\n  - {name: left, radius_m: 0.0325335425}\n"
                             "wheel_separation_m: 0.209077033\n") + kBounds);
  auto r = RunFitcal(dir, "simulate --out " + dir.Path("data") + " --seed 216251 --model "
                              "diff_drive --robot " + dir.Path("nominal.yaml") + " --truth " +
                              dir.Path("truth.yaml") + " --repetitions 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunFitcal(dir, "diagnose --logs " + dir.Path("data") + " --out " + dir.Path("diag") +
                         " --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  // The track fit is selected (before, the declared fit, after the track fit gave way on its
  // bounds: its propagated sigmas, as wide as its residuals, would have let it pass the check below).
  const std::size_t selected = r.out.find("<- selected");
  ASSERT_NE(selected, std::string::npos) << r.out;
  const std::size_t line = r.out.rfind('\n', selected);
  EXPECT_TRUE(Has(r.out.substr(line, selected - line), "track fit")) << r.out;
  fitcal::testing::ExpectEveryParameterWithin3WrittenSigmas(dir.Path("diag") + "/calibrated.yaml",
                                                           dir.Path("truth.yaml"));
}

}  // namespace diagnose_far_guess_cli_test
