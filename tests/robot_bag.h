#pragma once
// A simulated differential drive (sim/, kDiffDriveExampleYaml's model at kTruth) recorded
// as a ROS 2 bag the way a robot records it - sensor_msgs/msg/JointState with cumulative wheel
// angles (an extra joint, not the robot's order, rest messages between runs) and
// geometry_msgs/msg/PoseStamped ground truth, header stamps, the recording time a few ms later,
// split in two files - written with the project's own writer (io/rosbag2/bag_writer.h). Shared by
// the import's library tests (ros2_io_test), its command-line tests (rosbag2_cli_test) and the
// documented commands (robot_bag_writer, docs_commands_test).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "tests/bags/bag_writer.h"
#include "tests/bags/ros_message_encoders.h"
#include "io/rosbag2/ros_messages.h"
#include "models/model_interface.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"

namespace fitcal::testing::robot_bag {

namespace fs = std::filesystem;
using namespace io::rosbag2;

inline const std::vector<double> kTruth = {0.0426, 0.0414, 0.2065};  // r_right, r_left, b
constexpr std::int64_t kEpochNs = 1700000000000000000;  // the bags' clock origin
constexpr double kGapS = 3.0;                           // rest between runs
constexpr double kEncoderPeriodS = 0.05;

inline std::int64_t Ns(double t_s) { return kEpochNs + std::llround(t_s * 1e9); }

inline std::vector<sim::ModelSimulatedRun> SimulatedRuns(const RobotModelInterface& model) {
  sim::SimulationOptions o;
  o.encoder_period_s = kEncoderPeriodS;
  o.gt_position_sigma_m = 0.001;
  o.gt_heading_sigma_rad = 0.2 * M_PI / 180.0;
  o.wheel_rate_sigma_rad_s = 0.01;
  o.seed = 18;
  sim::DiffDriveTrajectoryOptions shapes;
  shapes.circle_laps = 0.75;  // open arcs: their end poses see the scale
  return sim::SimulateRuns(model, kTruth, sim::DiffDriveCalibrationTrajectories(2, shapes), o);
}

// What real recorders do to a bag, applied while it is written.
struct BagEdits {
  std::function<void(std::size_t, JointState*)> joint;  // message index on /joint_states
  std::function<void(std::size_t, PoseStamped*)> pose;  // message index on /mocap/pose
  bool other_node = false;  // a second node's JointState (other joints) after every 7th message
  std::int64_t clock_step_back_ns = 0;  // recording times of the second half moved back by this
  bool split_in_two = true;  // the recorder's --max-bag-size reached half way: two files
  // A LiDAR odometry instead of the motion capture: nav_msgs/msg/Odometry on /lidar/odom whose
  // child frame `lidar` sits at base_T_lidar (the base's poses carried there), and, when not
  // empty, these transforms on /tf_static (one message at the start).
  std::optional<Pose2d> base_T_lidar;
  std::vector<TransformStamped> tf_static;
};

// world_T_base composed with base_T_sensor: the sensor's pose in the world.
inline Pose2d SensorPose(const Pose2d& world_T_base, const Pose2d& base_T_sensor) {
  const double c = std::cos(world_T_base.theta), s = std::sin(world_T_base.theta);
  return {world_T_base.x + c * base_T_sensor.x - s * base_T_sensor.y,
          world_T_base.y + s * base_T_sensor.x + c * base_T_sensor.y,
          world_T_base.theta + base_T_sensor.theta};
}

// The bag: runs one after the other on one clock (run i starts where run i-1 ended + kGapS),
// joint states at rest in the gaps, no ground truth there (the robot is carried back to the start).
// Returns each run's span on the bag clock (s since the first message).
inline std::vector<std::pair<double, double>> WriteRobotBag(
    const fs::path& dir, const std::vector<sim::ModelSimulatedRun>& runs,
    BagWriterOptions options, const BagEdits& edits = {}) {
  struct Msg {
    bool joint;
    std::int64_t stamp_ns;
    std::vector<std::uint8_t> payload;
    const char* topic = nullptr;  // other than the two streams (/tf_static)
  };
  const char* pose_topic = edits.base_T_lidar ? "/lidar/odom" : "/mocap/pose";
  std::vector<Msg> msgs;
  std::vector<std::pair<double, double>> spans;
  double offset = 0.0, angle_right = 0.0, angle_left = 0.0;
  std::size_t joint_count = 0, pose_count = 0;
  const auto joint = [&](double t) {
    JointState js;
    js.header.stamp = {static_cast<std::int32_t>(Ns(t) / 1000000000),
                       static_cast<std::uint32_t>(Ns(t) % 1000000000)};
    js.name = {"caster", "left_wheel_joint", "right_wheel_joint"};  // not the robot's order
    js.position = {0.1, angle_left, angle_right};
    if (edits.joint) edits.joint(joint_count, &js);
    msgs.push_back({true, Ns(t), EncodeJointState(js)});
    if (edits.other_node && joint_count % 7 == 0) {
      JointState gripper;
      const std::int64_t ns = Ns(t) + 1000000;  // 1 ms later: between two of the robot's
      gripper.header.stamp = {static_cast<std::int32_t>(ns / 1000000000),
                              static_cast<std::uint32_t>(ns % 1000000000)};
      gripper.name = {"gripper_left_finger", "gripper_right_finger"};
      gripper.position = {0.01, -0.01};
      msgs.push_back({true, ns, EncodeJointState(gripper)});
    }
    ++joint_count;
  };
  for (const sim::ModelSimulatedRun& run : runs) {
    const std::vector<double>& t = run.log.encoders.t_s;
    for (std::size_t k = 0; k < t.size(); ++k) {
      if (k > 0) {  // recorded: mean rates over (t(k-1), t(k)]; the bag holds the angles
        angle_right += run.recorded[k][0] * (t[k] - t[k - 1]);
        angle_left += run.recorded[k][1] * (t[k] - t[k - 1]);
      }
      joint(offset + t[k] - t.front());
    }
    const GroundTruthTrack& gt = run.log.ground_truth;
    for (std::size_t k = 0; k < gt.t_s.size(); ++k) {
      PoseStamped p;
      const std::int64_t ns = Ns(offset + gt.t_s[k] - t.front());
      p.header.stamp = {static_cast<std::int32_t>(ns / 1000000000),
                        static_cast<std::uint32_t>(ns % 1000000000)};
      const Pose2d pose = edits.base_T_lidar ? SensorPose(gt.world_T_robot[k], *edits.base_T_lidar)
                                             : gt.world_T_robot[k];
      p.pose.position = {pose.x, pose.y, 0.0};
      p.pose.orientation = {0.0, 0.0, std::sin(pose.theta / 2), std::cos(pose.theta / 2)};
      if (edits.pose) edits.pose(pose_count, &p);
      ++pose_count;
      if (edits.base_T_lidar) {
        Odometry o;
        o.header = {p.header.stamp, "odom"};
        o.child_frame_id = "lidar";
        o.pose.pose = p.pose;
        msgs.push_back({false, ns, EncodeOdometry(o)});
      } else {
        msgs.push_back({false, ns, EncodePoseStamped(p)});
      }
    }
    spans.emplace_back(offset, offset + t.back() - t.front());
    offset += t.back() - t.front();
    const int gap_steps = static_cast<int>(std::lround(kGapS / kEncoderPeriodS));
    for (int i = 1; i < gap_steps; ++i) joint(offset + i * kEncoderPeriodS);
    offset += kGapS;
  }
  if (!edits.tf_static.empty()) {
    TfMessage tf{edits.tf_static};
    for (TransformStamped& t : tf.transforms) {
      t.header.stamp = {static_cast<std::int32_t>(Ns(0.0) / 1000000000),
                        static_cast<std::uint32_t>(Ns(0.0) % 1000000000)};
    }
    msgs.push_back({false, Ns(0.0), EncodeTfMessage(tf), "/tf_static"});
  }
  options.split_after_messages = edits.split_in_two ? msgs.size() / 2 + 1 : 0;
  BagWriter bag(dir.string(), options);
  bag.AddTopic("/joint_states", "sensor_msgs/msg/JointState");
  bag.AddTopic(pose_topic, edits.base_T_lidar ? "nav_msgs/msg/Odometry"
                                              : "geometry_msgs/msg/PoseStamped");
  bag.AddTopic("/chatter", "std_msgs/msg/String");
  if (!edits.tf_static.empty()) bag.AddTopic("/tf_static", "tf2_msgs/msg/TFMessage");
  std::stable_sort(msgs.begin(), msgs.end(),
                   [](const Msg& a, const Msg& b) { return a.stamp_ns < b.stamp_ns; });
  for (std::size_t i = 0; i < msgs.size(); ++i) {
    // Recorded 2.0-2.4 ms after the stamp (latency and jitter, below the message spacing).
    const std::int64_t recorded =
        msgs[i].stamp_ns + 2000000 + static_cast<std::int64_t>(i % 5) * 100000 -
        (i >= msgs.size() / 2 ? edits.clock_step_back_ns : 0);
    const char* topic = msgs[i].topic ? msgs[i].topic
                        : msgs[i].joint ? "/joint_states"
                                        : pose_topic;
    bag.Write(topic, recorded, ByteView(msgs[i].payload));
  }
  bag.Close();
  return spans;
}

}  // namespace fitcal::testing::robot_bag
