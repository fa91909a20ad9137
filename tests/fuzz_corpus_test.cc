// Replays the fuzz seed corpus (tests/fuzz/corpus/<target>/) and every input a fuzzer ever crashed
// on (tests/fuzz/regressions/<target>/) through the loaders, in the normal build and in the
// sanitizer build of tools/test.sh. A loader may accept an input or throw InputError; any other
// exception, a crash or a sanitizer report fails the test.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/fuzz/fuzz_support.h"

namespace fitcal::fuzz {
namespace {

namespace fs = std::filesystem;

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

int ReplayDirectory(const std::string& target, const fs::path& dir) {
  int count = 0;
  if (!fs::is_directory(dir)) return 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(RunFuzzTarget(target, ReadBytes(entry.path())));
    ++count;
  }
  return count;
}

TEST(FuzzCorpusTest, EveryTargetHasSeedsAndAllReplayWithoutCrash) {
  const fs::path root = fs::path(FITCAL_SOURCE_DIR) / "tests" / "fuzz";
  for (const std::string& target : FuzzTargetNames()) {
    SCOPED_TRACE(target);
    EXPECT_GE(ReplayDirectory(target, root / "corpus" / target), 3) << "seed corpus too small";
    ReplayDirectory(target, root / "regressions" / target);
  }
}

// The seeds are not just noise: the well-formed ones load.
TEST(FuzzCorpusTest, WellFormedSeedsLoad) {
  const fs::path root = fs::path(FITCAL_SOURCE_DIR) / "tests" / "fuzz" / "corpus";
  EXPECT_TRUE(RunFuzzTarget("encoder_csv", ReadBytes(root / "encoder_csv" / "basic.csv")));
  EXPECT_TRUE(RunFuzzTarget("encoder_csv", ReadBytes(root / "encoder_csv" / "bom_crlf.csv")));
  EXPECT_FALSE(RunFuzzTarget("encoder_csv", ReadBytes(root / "encoder_csv" / "nan.csv")));
  EXPECT_TRUE(
      RunFuzzTarget("ground_truth_csv", ReadBytes(root / "ground_truth_csv" / "basic.csv")));
  EXPECT_TRUE(RunFuzzTarget("tum", ReadBytes(root / "tum" / "basic.tum")));
  EXPECT_FALSE(RunFuzzTarget("tum", ReadBytes(root / "tum" / "bad_quaternion.tum")));
  EXPECT_TRUE(RunFuzzTarget("dataset_yaml", ReadBytes(root / "dataset_yaml" / "two_runs.yaml")));
  EXPECT_FALSE(RunFuzzTarget("dataset_yaml", ReadBytes(root / "dataset_yaml" / "outside.yaml")));
  EXPECT_FALSE(
      RunFuzzTarget("dataset_yaml", ReadBytes(root / "dataset_yaml" / "same_file_twice.yaml")));
  EXPECT_TRUE(RunFuzzTarget("robot_yaml", ReadBytes(root / "robot_yaml" / "apr02.yaml")));
  EXPECT_FALSE(RunFuzzTarget("robot_yaml", ReadBytes(root / "robot_yaml" / "lo_gt_hi.yaml")));
  EXPECT_TRUE(
      RunFuzzTarget("encoder_ticks_csv", ReadBytes(root / "encoder_ticks_csv" / "cumulative.csv")));
  EXPECT_TRUE(
      RunFuzzTarget("asoc_encoder_csv", ReadBytes(root / "asoc_encoder_csv" / "basic.csv")));
  EXPECT_FALSE(
      RunFuzzTarget("asoc_encoder_csv", ReadBytes(root / "asoc_encoder_csv" / "omni3_file.csv")));
  EXPECT_TRUE(RunFuzzTarget("asoc_robot_yaml", ReadBytes(root / "asoc_robot_yaml" / "proto.yaml")));
  EXPECT_FALSE(
      RunFuzzTarget("asoc_robot_yaml", ReadBytes(root / "asoc_robot_yaml" / "negative.yaml")));
}

TEST(FuzzCorpusTest, UnknownTargetIsRejected) {
  EXPECT_THROW(RunFuzzTarget("no_such_loader", ""), std::invalid_argument);
}

}  // namespace
}  // namespace fitcal::fuzz
