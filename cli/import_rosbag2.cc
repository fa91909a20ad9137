#include "cli/import_rosbag2.h"
#include "cli/cli_validators.h"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli/dataset_command.h"
#include "io/output_guard.h"

namespace fitcal::tools {

void AddImportRosbag2Options(CLI::App& app, ImportRosbag2Options& o) {
  app.add_option("bag", o.bag, "Bag directory, its metadata.yaml, or one .db3 / .mcap file")
      ->required();
  app.add_option("--out", o.out, "Output data set directory (written atomically)")->required();
  app.add_option("--robot", o.robot, "Robot YAML (any model); copied into the data set")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--encoders", o.encoders, "sensor_msgs/msg/JointState topic")
      ->capture_default_str();
  app.add_option("--joints", o.joints,
                 "Joint names in the robot's channel order (default: the channel names)")
      ->delimiter(',')
      ->check(JointNameValidator());
  app.add_option("--ground-truth", o.ground_truth,
                 "Ground-truth topic: geometry_msgs/msg/PoseStamped, nav_msgs/msg/Odometry or "
                 "tf2_msgs/msg/TFMessage")
      ->required();
  app.add_option("--ground-truth-frames", o.ground_truth_frames,
                 "For a TFMessage topic: parent:child of the transform, e.g. world:base_link; for "
                 "a PoseStamped: the child names the frame it tracks");
  app.add_option("--base-frame", o.base_frame,
                 "The robot's base frame in /tf_static: a ground truth tracking another frame "
                 "gets its nominal ground_truth_frame from there")
      ->capture_default_str();
  app.add_option("--stamp", o.stamp,
                 "header (default: when the driver measured; the recording time adds each "
                 "topic's own transport latency and jitter) or recorded")
      ->capture_default_str();
  app.add_option("--runs", o.runs, "Cut runs at these spans: t0:t1,t2:t3 (s since the bag start)");
  app.add_option("--split-at-rest", o.split_at_rest_s,
                 "Cut runs in the middle of every rest at least this long (s)")
      ->check(PositiveNumber());
  app.add_option("--rest-rate", o.rest_rate_rad_s, "A wheel slower than this is at rest (rad/s)")
      ->capture_default_str()
      ->check(PositiveNumber());
  app.add_option("--label", o.label, "Trajectory label of the runs (default: the bag's name)");
  app.add_flag("--force", o.force, io::kForceDirectoryHelp);
  app.add_flag("--skip-mapping-check", o.skip_mapping_check,
               "Write even when another order or sign of the joints explains the ground truth "
               "far better (exit 4 otherwise)");
}

int RunImportRosbag2Command(const ImportRosbag2Options& o) {
  return RunReportingErrors("fitcal import rosbag2", [&]() -> int {
    const Rosbag2Import imp = ImportRosbag2(o);
    if (!o.quiet) {
      for (const std::string& note : imp.notes) std::printf("%s\n", note.c_str());
      std::printf(
          "wrote %zu run(s) to %s (%.1f MB of bag, %zu encoder and %zu ground-truth "
          "samples); nominal CF (Eq. 14) %.4f\n",
          imp.runs.size(), o.out.c_str(), static_cast<double>(imp.streams.bytes) * 1e-6,
          imp.streams.joints.t_ns.size(), imp.streams.poses.t_ns.size(), imp.nominal.cf);
    }
    return 0;
  });
}

}  // namespace fitcal::tools
