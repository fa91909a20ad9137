// The loaders under fuzzing, one line each (X-macro list, included by fuzz_support.cc; no include
// guard on purpose). tests/fuzz/CMakeLists.txt reads the names from the lines below, so adding a
// loader is one line here:
//
//   FITCAL_FUZZ_TARGET(name, "file the input is written to", statement using `path` and `dir`)
//
// The statement may throw fitcal::io::InputError (bad input, reported to the user); any other
// exception, a crash or a sanitizer report is a bug. `dir` also holds a valid robot.yaml, enc.csv
// and gt.csv (fuzz_support.cc) for loaders that follow paths, and diff_drive.yaml for the rosbag2
// import (one bag file, MCAP or sqlite3: `fitcal import rosbag2` without writing).
FITCAL_FUZZ_TARGET(encoder_csv, "run.csv", FuzzEncoderCsv(path, std::nullopt))
FITCAL_FUZZ_TARGET(encoder_ticks_csv, "ticks.csv", FuzzEncoderCsv(path, EncoderTicks{4096.0, true}))
FITCAL_FUZZ_TARGET(ground_truth_csv, "gt_fuzz.csv", FuzzGroundTruth(path))
FITCAL_FUZZ_TARGET(tum, "gt_fuzz.tum", FuzzGroundTruth(path))
FITCAL_FUZZ_TARGET(dataset_yaml, "dataset.yaml", FuzzDataset(dir))
FITCAL_FUZZ_TARGET(robot_yaml, "robot_fuzz.yaml", FuzzOmni3Robot(path))
FITCAL_FUZZ_TARGET(asoc_encoder_csv, "asoc.csv", io::ReadAsocEncoderCsv(path))
FITCAL_FUZZ_TARGET(asoc_robot_yaml, "asoc_fuzz.yaml", FuzzAsocRobot(path))
FITCAL_FUZZ_TARGET(rosbag2_mcap, "fuzz_bag.mcap", FuzzRosbag2Import(path, dir))
FITCAL_FUZZ_TARGET(rosbag2_db3, "fuzz_bag.db3", FuzzRosbag2Import(path, dir))
