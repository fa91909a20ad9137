#pragma once
// `fitcal import rosbag2 <bag> --out <data set> --robot <robot.yaml> --ground-truth <topic>`:
// the bag read and cut into runs by interchange/ros2/rosbag2_import.h (what the import reads,
// repairs and refuses is said there), then the data set written: robot.yaml (the robot file as
// given, with the ground truth's frame from /tf_static when found), dataset.yaml, and per run
// runs/<id>_encoders.csv and runs/<id>_ground_truth.csv.
//
// Nothing is written unless every run is good: the data set is built in a temporary sibling of
// --out, read back with the loader `fit` uses (the import never writes a data set `fit`
// refuses) and renamed into place (io/staged_directory.h).

#include "interchange/ros2/rosbag2_import.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

// ReadRosbag2Import, then writes the data set atomically. Throws as ReadRosbag2Import, and
// std::runtime_error when --out exists (without force) or cannot be written.
// The command: one line `fitcal import rosbag2: <file>: <what>` on stderr and exit 1 for bad
// input or an unwritable output, 2 for bad options; 0 after writing.
// Declares every flag of `import rosbag2` on its subcommand `app`, bound to `options`.
void AddImportRosbag2Options(CLI::App& app, ImportRosbag2Options& options);

int RunImportRosbag2Command(const ImportRosbag2Options& options);

}  // namespace fitcal::tools
