// Trajectory strategies of Palacin Table 4 (fit/strategies.h): the printed lists, label-list
// parsing and run selection.

#include "fit/strategies.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "tests/model_support.h"

namespace fitcal {
namespace {

using Labels = std::vector<std::string>;

TEST(Strategies, MatchPalacinTable4) {
  // Palacin Sec. 3.2: STA R1, R5, R9; STB B2, B6, B10, G12, G4, G8; STC R1-R12; STD all B and G;
  // STE all 36.
  const auto& s = PalacinStrategies();
  ASSERT_EQ(s.size(), 5u);
  EXPECT_EQ(s[0].name, "STA");
  EXPECT_EQ(s[0].labels, (Labels{"R1", "R5", "R9"}));
  EXPECT_EQ(s[1].name, "STB");
  EXPECT_EQ(s[1].labels, (Labels{"B2", "B6", "B10", "G12", "G4", "G8"}));
  EXPECT_EQ(s[2].name, "STC");
  EXPECT_EQ(s[2].labels.size(), 12u);
  EXPECT_EQ(s[2].labels.front(), "R1");
  EXPECT_EQ(s[2].labels.back(), "R12");
  EXPECT_EQ(s[3].name, "STD");
  EXPECT_EQ(s[3].labels.size(), 24u);
  for (const std::string& label : s[3].labels) EXPECT_TRUE(label[0] == 'B' || label[0] == 'G');
  EXPECT_EQ(s[4].name, "STE");
  EXPECT_EQ(s[4].labels.size(), 36u);
}

TEST(Strategies, ParsesNamesListsAndRanges) {
  EXPECT_EQ(ParseStrategy("stb").labels, PalacinStrategies()[1].labels);
  EXPECT_EQ(ParseStrategy("STE").name, "STE");
  const TrajectoryStrategy list = ParseStrategy("R1-R3, G12,B7");
  EXPECT_EQ(list.name, "R1-R3, G12,B7");
  EXPECT_EQ(list.labels, (Labels{"R1", "R2", "R3", "G12", "B7"}));
  // Labels of other data sets pass through unchanged.
  EXPECT_EQ(ParseStrategy("square_cw").labels, (Labels{"square_cw"}));
}

TEST(Strategies, RejectsMalformedLists) {
  for (const char* bad : {"", "R1,,R2", "R3-R1", "R1-G3", "R1-", "R1,R1", "R1-R3,R2"}) {
    EXPECT_THROW(ParseStrategy(bad), std::invalid_argument) << bad;
  }
}

TEST(Strategies, SelectsByTrajectoryAndRepetitionInDataOrder) {
  std::vector<AlignedRun> runs;
  for (int rep = 1; rep <= 3; ++rep) {
    for (const char* label : {"R1", "R2", "R5", "R9", "G4"}) runs.push_back(testing::LabelledRun(label, rep));
  }
  const TrajectoryStrategy sta = ParseStrategy("STA");
  const std::vector<AlignedRun> selected = SelectRuns(runs, sta, {1, 3});
  std::vector<std::string> ids;
  for (const AlignedRun& run : selected) ids.push_back(run.id);
  EXPECT_EQ(ids, (Labels{"R1-1", "R5-1", "R9-1", "R1-3", "R5-3", "R9-3"}));
  EXPECT_TRUE(MissingTrajectories(runs, sta).empty());
  EXPECT_EQ(MissingTrajectories(runs, ParseStrategy("G4,G8,B2")), (Labels{"G8", "B2"}));
  EXPECT_TRUE(SelectRuns(runs, sta, {4}).empty());
}

}  // namespace
}  // namespace fitcal
