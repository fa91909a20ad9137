// Replays the fuzz seed corpus (tests/fuzz/corpus/<target>/) and every input a fuzzer ever crashed
// on (tests/fuzz/regressions/<target>/) through the loaders, in the normal build and in the
// sanitizer build of tools/test.sh. A loader may accept an input or throw InputError; any other
// exception, a crash or a sanitizer report fails the test. The rosbag2 seeds (tiny bags the
// writer makes, MCAP and sqlite3) are also mutated here - bit flips, overwritten bytes and length
// fields, truncations - so every ctest run feeds the bag readers a few thousand malformed files.
// Rewrite the seeds with FITCAL_WRITE_ROSBAG2_SEEDS=1 (after a change to the writer), then shrink
// the .db3 ones below 20 KB: `sqlite3 <seed>.db3 'PRAGMA page_size=512; VACUUM;'`.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "tests/bags/bag_writer.h"
#include "tests/bags/ros_message_encoders.h"
#include "io/rosbag2/ros_messages.h"
#include "tests/fuzz/fuzz_support.h"
#include "tests/test_files.h"

namespace fitcal::fuzz {
namespace {

namespace fs = std::filesystem;
using fitcal::testing::ReadFileBytes;

int ReplayDirectory(const std::string& target, const fs::path& dir) {
  int count = 0;
  if (!fs::is_directory(dir)) return 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(RunFuzzTarget(target, ReadFileBytes(entry.path())));
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
  EXPECT_TRUE(RunFuzzTarget("encoder_csv", ReadFileBytes(root / "encoder_csv" / "basic.csv")));
  EXPECT_TRUE(RunFuzzTarget("encoder_csv", ReadFileBytes(root / "encoder_csv" / "bom_crlf.csv")));
  EXPECT_FALSE(RunFuzzTarget("encoder_csv", ReadFileBytes(root / "encoder_csv" / "nan.csv")));
  EXPECT_TRUE(
      RunFuzzTarget("ground_truth_csv", ReadFileBytes(root / "ground_truth_csv" / "basic.csv")));
  EXPECT_TRUE(RunFuzzTarget("tum", ReadFileBytes(root / "tum" / "basic.tum")));
  EXPECT_FALSE(RunFuzzTarget("tum", ReadFileBytes(root / "tum" / "bad_quaternion.tum")));
  EXPECT_TRUE(
      RunFuzzTarget("dataset_yaml", ReadFileBytes(root / "dataset_yaml" / "two_runs.yaml")));
  EXPECT_FALSE(
      RunFuzzTarget("dataset_yaml", ReadFileBytes(root / "dataset_yaml" / "outside.yaml")));
  EXPECT_FALSE(
      RunFuzzTarget("dataset_yaml", ReadFileBytes(root / "dataset_yaml" / "same_file_twice.yaml")));
  EXPECT_TRUE(RunFuzzTarget("robot_yaml", ReadFileBytes(root / "robot_yaml" / "apr02.yaml")));
  EXPECT_FALSE(RunFuzzTarget("robot_yaml", ReadFileBytes(root / "robot_yaml" / "lo_gt_hi.yaml")));
  EXPECT_TRUE(RunFuzzTarget("encoder_ticks_csv",
                            ReadFileBytes(root / "encoder_ticks_csv" / "cumulative.csv")));
  EXPECT_TRUE(
      RunFuzzTarget("asoc_encoder_csv", ReadFileBytes(root / "asoc_encoder_csv" / "basic.csv")));
  EXPECT_FALSE(RunFuzzTarget("asoc_encoder_csv",
                             ReadFileBytes(root / "asoc_encoder_csv" / "omni3_file.csv")));
  EXPECT_TRUE(
      RunFuzzTarget("asoc_robot_yaml", ReadFileBytes(root / "asoc_robot_yaml" / "proto.yaml")));
  EXPECT_FALSE(
      RunFuzzTarget("asoc_robot_yaml", ReadFileBytes(root / "asoc_robot_yaml" / "negative.yaml")));
}

// A tiny bag as a robot records it: JointState (an extra joint, not the robot's order) at 20 Hz,
// PoseStamped at 10 Hz; one storage file (seeds are single files), recorded 2 ms after the stamp.
std::string TinyBag(const fs::path& dir, io::rosbag2::BagWriterOptions options, int messages) {
  namespace rb = io::rosbag2;
  constexpr std::int64_t kEpochNs = 1700000000000000000;
  const auto stamp = [](std::int64_t ns) {
    return rb::Time{static_cast<std::int32_t>(ns / 1000000000),
                    static_cast<std::uint32_t>(ns % 1000000000)};
  };
  rb::BagWriter bag(dir.string(), options);
  bag.AddTopic("/joint_states", "sensor_msgs/msg/JointState");
  bag.AddTopic("/mocap/pose", "geometry_msgs/msg/PoseStamped");
  for (int i = 0; i < messages; ++i) {
    const std::int64_t ns = kEpochNs + i * 50000000;
    rb::JointState js;
    js.header.stamp = stamp(ns);
    js.name = {"caster", "left_wheel_joint", "right_wheel_joint"};
    js.position = {0.1, 0.5 * i, 0.6 * i};
    bag.Write("/joint_states", ns + 2000000, rb::ByteView(rb::EncodeJointState(js)));
    if (i % 2 == 0) {
      rb::PoseStamped p;
      p.header.stamp = stamp(ns);
      p.pose.position = {0.01 * i, 0.001 * i, 0.0};
      p.pose.orientation = {0.0, 0.0, std::sin(0.01 * i), std::cos(0.01 * i)};
      bag.Write("/mocap/pose", ns + 2000000, rb::ByteView(rb::EncodePoseStamped(p)));
    }
  }
  bag.Close();
  return bag.files().front();
}

TEST(FuzzCorpusTest, Rosbag2SeedsAreTinyBags) {
  namespace rb = io::rosbag2;
  const fs::path root = fs::path(FITCAL_SOURCE_DIR) / "tests" / "fuzz" / "corpus";
  const fs::path tmp =
      fs::temp_directory_path() / ("fitcal-fuzz-seeds-" + std::to_string(getpid()));
  struct Seed {
    const char* target;
    const char* name;
    rb::BagWriterOptions options;
    int messages = 8;
  };
  std::vector<Seed> seeds = {
      {"rosbag2_mcap", "chunked.mcap", {}}, {"rosbag2_mcap", "zstd.mcap", {}},
      {"rosbag2_mcap", "lz4.mcap", {}},     {"rosbag2_mcap", "unchunked_no_summary.mcap", {}},
      {"rosbag2_db3", "basic.db3", {}},     {"rosbag2_db3", "shortest.db3", {}, 3},
      {"rosbag2_db3", "longer.db3", {}, 20}};
  seeds[1].options.mcap.compression = rb::Compression::kZstd;
  seeds[2].options.mcap.compression = rb::Compression::kLz4;
  seeds[3].options.mcap.chunked = false;
  seeds[3].options.mcap.summary = false;
  for (std::size_t i = 4; i < seeds.size(); ++i)
    seeds[i].options.storage = rb::StorageFormat::kSqlite3;
  const bool write = std::getenv("FITCAL_WRITE_ROSBAG2_SEEDS") != nullptr;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    SCOPED_TRACE(seeds[i].name);
    const std::string bytes = ReadFileBytes(
        TinyBag(tmp / ("bag" + std::to_string(i)), seeds[i].options, seeds[i].messages));
    EXPECT_TRUE(RunFuzzTarget(seeds[i].target, bytes));  // what the writer makes imports
    const fs::path seed = root / seeds[i].target / seeds[i].name;
    if (write) {
      fs::create_directories(seed.parent_path());
      std::ofstream(seed, std::ios::binary) << bytes;
    }
    EXPECT_LT(fs::file_size(seed), 20000u) << "keep checked-in seeds tiny";
    EXPECT_TRUE(RunFuzzTarget(seeds[i].target, ReadFileBytes(seed)));
  }
  std::error_code ignored;
  fs::remove_all(tmp, ignored);
}

// Deterministic mutations of every rosbag2 seed: the bag code must accept or throw InputError
// (one line), never crash, hang or read out of bounds (the sanitizer build checks the latter).
TEST(FuzzCorpusTest, MutatedBagsFailCleanly) {
  const fs::path root = fs::path(FITCAL_SOURCE_DIR) / "tests" / "fuzz" / "corpus";
  std::mt19937 rng(18);
  int inputs = 0, rejected = 0;
  for (const char* target : {"rosbag2_mcap", "rosbag2_db3"}) {
    for (const auto& entry : fs::directory_iterator(root / target)) {
      const std::string seed = ReadFileBytes(entry.path());
      ASSERT_FALSE(seed.empty());
      const auto run = [&](const std::string& bytes, const std::string& how) {
        SCOPED_TRACE(entry.path().filename().string() + ": " + how);
        bool accepted = true;
        EXPECT_NO_THROW(accepted = RunFuzzTarget(target, bytes));
        ++inputs;
        rejected += accepted ? 0 : 1;
      };
      for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{8},
                            seed.size() / 3, seed.size() / 2, seed.size() - 1}) {
        run(seed.substr(0, n), "truncated to " + std::to_string(n));
      }
      std::uniform_int_distribution<std::size_t> at(0, seed.size() - 1);
      for (int i = 0; i < 150; ++i) {
        std::string bytes = seed;
        const std::size_t where = at(rng);
        std::string how;
        switch (i % 5) {
          case 0:  // one bit
            bytes[where] = static_cast<char>(bytes[where] ^ (1 << (rng() % 8)));
            how = "bit flip";
            break;
          case 1:  // a random byte
            bytes[where] = static_cast<char>(rng());
            how = "byte";
            break;
          case 2:  // a huge length or count field
            for (std::size_t k = where; k < std::min(bytes.size(), where + 4); ++k)
              bytes[k] = '\xff';
            how = "0xffffffff";
            break;
          case 3:  // a length field of a few bytes more or less
            bytes[where] = static_cast<char>(bytes[where] + static_cast<int>(rng() % 9) - 4);
            how = "off by a few";
            break;
          default:  // several bytes, then cut
            for (int k = 0; k < 8; ++k) bytes[at(rng)] = static_cast<char>(rng());
            bytes.resize(std::max(where, bytes.size() / 2));
            how = "scrambled and cut";
        }
        run(bytes, how + " at byte " + std::to_string(where));
      }
    }
  }
  EXPECT_GT(inputs, 500);
  EXPECT_GT(rejected, inputs / 4);  // the mutations do reach the checks
}

TEST(FuzzCorpusTest, UnknownTargetIsRejected) {
  EXPECT_THROW(RunFuzzTarget("no_such_loader", ""), std::invalid_argument);
}

}  // namespace
}  // namespace fitcal::fuzz
