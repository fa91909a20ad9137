// Flags that no test ran through the command line before (issue 43 item 5), each checked for its
// effect on what the command writes, not only for its exit status.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "models/model_registry.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

using testing::RunFitcal;
using testing::TempDir;

const std::string kFlower = std::string(FITCAL_SOURCE_DIR) + "/data/flower";

// fit --hold: the held parameters are written at their nominal values, bit for bit as the robot
// YAML gives them (the YAML holds degrees: a round trip through radians may move the last of 17
// digits, hence 1e-12 rad), while the free ones move (without the hold every delta moves too: the
// flower's true angles differ from the nominal by up to 1.6 deg, README).
TEST(FitHold, HeldParametersStayAtTheNominalAndTheOthersMove) {
  TempDir tmp;
  const std::string held = tmp.Path("held.yaml"), free = tmp.Path("free.yaml");
  const testing::FitcalRun h =
      RunFitcal(tmp, "fit --logs " + kFlower + " --hold delta_a,delta_b,delta_c --out " + held);
  ASSERT_EQ(h.exit_code, 0) << h.err;
  const testing::FitcalRun f = RunFitcal(tmp, "fit --logs " + kFlower + " --out " + free);
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const Robot nominal = ReadRobotModelFile(kFlower + "/robot.yaml")->robot();
  const Robot with_hold = ReadRobotModelFile(held)->robot();
  const Robot without = ReadRobotModelFile(free)->robot();
  for (const char* name : {"delta_a", "delta_b", "delta_c"}) {
    const int k = RequireParameterIndex(nominal, name);
    EXPECT_NEAR(with_hold.nominal[k], nominal.nominal[k], 1e-12) << name;
    EXPECT_GT(std::abs(without.nominal[k] - nominal.nominal[k]), 1e-4) << name;
  }
  for (const char* name : {"R_a", "R_b", "R_c"}) {
    const int k = RequireParameterIndex(nominal, name);
    EXPECT_GT(std::abs(with_hold.nominal[k] - nominal.nominal[k]), 1e-3) << name;
  }
}

}  // namespace
}  // namespace fitcal
