#pragma once
// The mount of a bag's ground-truth sensor from the bag's own /tf_static: the planar pose of the
// frame the ground truth tracks (a LiDAR or visual odometry's child frame) in the robot's base
// frame, composed in 3-D along the transform tree (base -> ... -> sensor, or through a common
// ancestor) and projected to the plane (x, y of the translation; the yaw of the rotation, as
// YawOfQuaternion). fitcal's nominal `ground_truth_frame:` (docs/dataset-format.md).

#include <optional>
#include <string>
#include <vector>

#include "io/rosbag2/bag_streams.h"
#include "odometry/pose2.h"

namespace fitcal::io::rosbag2 {

struct StaticMount {
  std::optional<Pose2d> base_T_sensor;  // set when /tf_static links the two frames
  std::string chain;                    // "base_link -> lidar_mount -> lidar", with base_T_sensor
};

// base_T_child from `transforms` (tf2's convention: a TransformStamped gives the child frame's
// pose in header.frame_id; a leading '/' of a frame id is ignored); nullopt when the two frames
// are not in one tree. A frame published twice keeps its last transform, as tf2 does.
StaticMount StaticTransformBetween(const std::vector<TransformStamped>& transforms,
                                   const std::string& base_frame, const std::string& child_frame);

// What an import writes for the frame the ground truth tracks (streams.pose_frame): a nominal
// `ground_truth_frame` from /tf_static when the bag links base_frame to it, and one line in
// words saying what was done (empty when the ground truth tracks base_frame itself, or names no
// frame and the bag has no /tf_static: nothing to say). A frame /tf_static puts on the base in the
// plane (base_footprint: a z offset) is the base: said, nothing written.
struct GroundTruthMountFromBag {
  std::optional<Pose2d> base_T_sensor;
  std::string note;
};
GroundTruthMountFromBag MountFromTfStatic(const BagStreams& streams, const std::string& topic,
                                          const std::string& base_frame);

}  // namespace fitcal::io::rosbag2
