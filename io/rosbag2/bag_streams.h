#pragma once
// The time series fitcal imports from a bag: the wheel (and steering) joints of one
// sensor_msgs/msg/JointState topic and a planar ground-truth pose from a
// geometry_msgs/msg/PoseStamped, nav_msgs/msg/Odometry or tf2_msgs/msg/TFMessage topic, read in
// one pass over the bag (BagReader: every file of a split bag, in recording order).
//
// Stamps. Each sample is stamped with its message's header stamp (the time the driver measured
// it) or with the bag's recording time (when the recorder received it; late by the transport
// latency and its jitter, which differ between topics), as the request says. Either way a
// stream's stamps must increase strictly; anything else is bad input (a driver that reuses a
// stamp, a bag of merged recordings), not something to sort away silently. One exception, said
// in a note: the recording clock stepped back (the recording times, in the order the recorder
// wrote them, go back by more than 10 ms). Then the reader's order by recording time interleaves
// two stretches of the recording; with header stamps each stream is put back in stamp order,
// and with recording times (--stamp recorded) the bag is refused at the instant of the step.
//
// Bad input (a topic missing or of the wrong type, a joint missing from a message, a message
// without the position or velocity of every joint, a non-finite value, a non-increasing stamp, no
// matching transform) throws io::InputError naming the bag file and the message.

#include <cstdint>
#include <string>
#include <vector>

#include "io/rosbag2/ros_messages.h"
#include "odometry/pose2.h"

namespace fitcal::io::rosbag2 {

enum class StampSource { kHeader, kRecorded };

struct BagStreamRequest {
  std::string joint_topic = "/joint_states";
  std::vector<std::string> joints;   // the joint names to read, in the caller's channel order
  std::vector<bool> needs_position;  // per joint: an angle reading (position) is required
  std::string pose_topic;            // PoseStamped, Odometry or TFMessage
  std::string parent_frame;          // TFMessage only: header.frame_id of the transform
  std::string child_frame;           // TFMessage: its child_frame_id; PoseStamped: the frame
                                     // it tracks (optional, BagStreams::pose_frame)
  StampSource stamp = StampSource::kHeader;
};

struct JointStream {
  std::vector<std::int64_t> t_ns;  // stamps, strictly increasing
  // Row-major, one row per stamp, one value per requested joint: positions (rad, cumulative
  // wheel angles) when every message carries them, else velocities (rad/s).
  std::vector<double> values;
  bool positions = true;
};

struct PoseStream {
  std::vector<std::int64_t> t_ns;     // strictly increasing
  std::vector<Pose2d> world_T_robot;  // yaw unwrapped (continuous across +-pi)
};

struct BagStreams {
  std::string bag;                 // the path given
  std::int64_t start_time_ns = 0;  // the bag's first recording time: the data set's t = 0
  std::uint64_t bytes = 0;         // size of the bag's storage files
  std::string pose_type;           // the ground-truth topic's message type
  // The frame whose pose the ground truth gives: an Odometry's child_frame_id (its first
  // message's), the child of a TFMessage's transform (request.child_frame), and for a
  // PoseStamped the child the request names (a PoseStamped's header.frame_id is the frame its
  // pose is expressed in, the world's, so it names none); empty when unknown.
  std::string pose_frame;
  // The bag's /tf_static (tf2_msgs/msg/TFMessage): every transform in recording order.
  bool has_tf_static = false;
  std::vector<TransformStamped> static_transforms;
  JointStream joints;
  PoseStream poses;
  std::vector<std::string> notes;  // what the reader repaired, one line each
};

// Reads both streams; throws io::InputError (see above).
BagStreams ReadBagStreams(const std::string& bag_path, const BagStreamRequest& request);

// Yaw (rad, about z) of a unit quaternion: atan2(2 (w z + x y), 1 - 2 (y^2 + z^2)).
double YawOfQuaternion(double x, double y, double z, double w);

}  // namespace fitcal::io::rosbag2
