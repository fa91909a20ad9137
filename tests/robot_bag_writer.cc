// robot_bag_writer <bag directory> <robot YAML> [mcap|sqlite3]
//
// Writes the simulated differential drive of tests/robot_bag.h as a ROS 2 bag (12 runs with 3 s
// rests between them, /joint_states and /mocap/pose, split in two files) and its nominal robot
// YAML: the recording a documented `fitcal import rosbag2` example reads when docs_commands_test
// runs it (a setup line of its doc-test annotation). Exit 0, or 2 with one line on bad usage.

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <exception>
#include <fstream>
#include <string>

#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "tests/robot_bag.h"

int main(int argc, char** argv) {
  using namespace fitcal;
  const std::string storage = argc == 4 ? argv[3] : "mcap";
  if ((argc != 3 && argc != 4) || (storage != "mcap" && storage != "sqlite3")) {
    std::fprintf(stderr, "usage: robot_bag_writer <bag directory> <robot YAML> [mcap|sqlite3]\n");
    return 2;
  }
  try {
    const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), argv[2]);
    io::rosbag2::BagWriterOptions options;
    options.storage = storage == "mcap" ? io::rosbag2::StorageFormat::kMcap
                                        : io::rosbag2::StorageFormat::kSqlite3;
    testing::robot_bag::WriteRobotBag(argv[1], testing::robot_bag::SimulatedRuns(*model), options);
    std::ofstream(argv[2], std::ios::trunc) << kDiffDriveExampleYaml;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robot_bag_writer: %s\n", e.what());
    return 1;
  }
  return 0;
}
