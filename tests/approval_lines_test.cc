// The approval tests' matcher itself (tests/approval_lines.h): whole numbers exactly, fractions to
// one unit in their last printed digit, lines only within their block.

#include "tests/approval_lines.h"

#include <gtest/gtest.h>

namespace fitcal::testing {
namespace {

bool Matches(const std::string& want, const std::string& got) {
  return LineMatches(Tokens(want), Tokens(got));
}

TEST(ApprovalLines, WholeNumbersMatchExactly) {
  // The mutation of issue 43 the old matcher let through: "drift 2 m" read as "drift 1 m".
  EXPECT_FALSE(Matches("drift 1 m [%] (342 windows)", "drift 2 m [%] (342 windows)"));
  EXPECT_FALSE(Matches("drift 2 m [%] (342 windows)", "drift 1 m [%] (342 windows)"));
  EXPECT_FALSE(Matches("| fit | 120 | 240 |", "| fit | 121 | 240 |"));
  EXPECT_TRUE(Matches("drift 1 m [%] (342 windows)", "drift 1 m [%] (342 windows)"));
  EXPECT_FALSE(Matches("(342 windows)", "(343 windows)"));  // a token with brackets: words
}

TEST(ApprovalLines, FractionsMatchToOneUnitInTheirLastDigit) {
  EXPECT_TRUE(Matches("CF 0.0075 -82.0%", "CF 0.0076 -81.9%"));
  EXPECT_TRUE(Matches("CF 0.0075", "CF 0.0074"));
  EXPECT_FALSE(Matches("CF 0.0075", "CF 0.0077"));
  EXPECT_FALSE(Matches("CF 0.0075 -82.0%", "CF 0.0075 -82.2%"));
  EXPECT_FALSE(Matches("CF 0.0075", "CF 0.0075 extra"));
  EXPECT_FALSE(Matches("nominal 0.0075", "fit 0.0075"));
}

TEST(ApprovalLines, ALineMatchesOnlyWithinItsBlock) {
  const std::string out =
      "  A: fit      nominal calibrated\n"
      "  ATE RMSE [m]    0.0269     0.0048\n"
      "\n"
      "  B: fit      nominal calibrated\n"
      "  ATE RMSE [m]    0.0300     0.0100\n";
  EXPECT_TRUE(
      MissingFromBlock(out, {"  A: fit nominal calibrated", "ATE RMSE [m] 0.0269 0.0048"}).empty());
  // B's header with A's figures: each line is printed somewhere, but not in one block.
  const std::vector<std::string> missing =
      MissingFromBlock(out, {"  B: fit nominal calibrated", "ATE RMSE [m] 0.0269 0.0048"});
  EXPECT_EQ(missing.size(), 1u);
}

}  // namespace
}  // namespace fitcal::testing
