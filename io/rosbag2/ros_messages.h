#pragma once
// The ROS 2 message types fitcal reads from bags, as plain structs, with CDR decoders (the tests'
// encoders and test messages: tests/bags/). Field lists and order follow the .msg files:
//   builtin_interfaces/msg/Time   int32 sec, uint32 nanosec
//   std_msgs/msg/Header           builtin_interfaces/Time stamp, string frame_id
//   sensor_msgs/msg/JointState    Header header, string[] name, float64[] position,
//                                 float64[] velocity, float64[] effort
//   geometry_msgs/msg/PoseStamped Header header, Pose pose (Point position, Quaternion orientation)
//   nav_msgs/msg/Odometry         Header header, string child_frame_id,
//                                 PoseWithCovariance pose (Pose pose, float64[36] covariance),
//                                 TwistWithCovariance twist (Twist twist, float64[36] covariance)
//   tf2_msgs/msg/TFMessage        geometry_msgs/TransformStamped[] transforms
//   geometry_msgs/msg/TransformStamped  Header header, string child_frame_id,
//                                 Transform transform (Vector3 translation, Quaternion rotation)
// (ros2/common_interfaces, ros2/geometry2).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/rosbag2/bytes.h"

namespace fitcal::io::rosbag2 {

struct Time {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  std::int64_t ToNanoseconds() const { return std::int64_t{sec} * 1000000000 + nanosec; }
};
struct Header {
  Time stamp;
  std::string frame_id;
};
struct Vector3 {
  double x = 0, y = 0, z = 0;
};
struct Point {
  double x = 0, y = 0, z = 0;
};
struct Quaternion {
  double x = 0, y = 0, z = 0, w = 1;
};
struct Pose {
  Point position;
  Quaternion orientation;
};
struct Twist {
  Vector3 linear;   // m/s
  Vector3 angular;  // rad/s
};
struct PoseWithCovariance {
  Pose pose;
  std::array<double, 36> covariance{};  // row-major 6x6 (x, y, z, rot x, rot y, rot z)
};
struct TwistWithCovariance {
  Twist twist;
  std::array<double, 36> covariance{};
};
struct Transform {
  Vector3 translation;
  Quaternion rotation;
};
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  Transform transform;
};

struct JointState {  // sensor_msgs/msg/JointState
  Header header;
  std::vector<std::string> name;
  std::vector<double> position;  // rad or m
  std::vector<double> velocity;  // rad/s or m/s
  std::vector<double> effort;    // N m or N
};
struct PoseStamped {  // geometry_msgs/msg/PoseStamped
  Header header;
  Pose pose;
};
struct Odometry {  // nav_msgs/msg/Odometry
  Header header;
  std::string child_frame_id;
  PoseWithCovariance pose;
  TwistWithCovariance twist;
};
struct TfMessage {  // tf2_msgs/msg/TFMessage
  std::vector<TransformStamped> transforms;
};

// Decoders. `what` names the message in errors (see Describe in bag_reader.h); each throws one
// InputError for a payload that is short, has a bad string or an impossible sequence length.
JointState DecodeJointState(ByteView payload, const std::string& what);
PoseStamped DecodePoseStamped(ByteView payload, const std::string& what);
Odometry DecodeOdometry(ByteView payload, const std::string& what);
TfMessage DecodeTfMessage(ByteView payload, const std::string& what);

}  // namespace fitcal::io::rosbag2
