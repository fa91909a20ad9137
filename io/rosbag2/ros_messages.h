#pragma once
// The ROS 2 message types fitcal reads from bags, as plain structs, with CDR decoders (and
// encoders for the writer and tests). Field lists and order follow the .msg files:
//   builtin_interfaces/msg/Time   int32 sec, uint32 nanosec
//   std_msgs/msg/Header           builtin_interfaces/Time stamp, string frame_id
//   std_msgs/msg/String           string data
//   sensor_msgs/msg/JointState    Header header, string[] name, float64[] position,
//                                 float64[] velocity, float64[] effort
//   geometry_msgs/msg/PoseStamped Header header, Pose pose (Point position, Quaternion orientation)
//   nav_msgs/msg/Odometry         Header header, string child_frame_id,
//                                 PoseWithCovariance pose (Pose pose, float64[36] covariance),
//                                 TwistWithCovariance twist (Twist twist, float64[36] covariance)
//   tf2_msgs/msg/TFMessage        geometry_msgs/TransformStamped[] transforms
//   geometry_msgs/msg/TransformStamped  Header header, string child_frame_id,
//                                 Transform transform (Vector3 translation, Quaternion rotation)
// (ros2/common_interfaces, ros2/geometry2) and, for the test bags, test_msgs/msg/BasicTypes and
// test_msgs/msg/Arrays (ros2/rcl_interfaces; the exact text is stored in the bags themselves, in
// the sqlite3 message_definitions table and the MCAP Schema records).

#include <array>
#include <cstdint>
#include <string>
#include <variant>
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
struct StringMessage {  // std_msgs/msg/String
  std::string data;
};

// test_msgs/msg/BasicTypes (also the layout of test_msgs/msg/Defaults). ROS 2 `byte` and `char`
// are both unsigned 8-bit.
struct BasicTypes {
  bool bool_value = false;
  std::uint8_t byte_value = 0;
  std::uint8_t char_value = 0;
  float float32_value = 0;
  double float64_value = 0;
  std::int8_t int8_value = 0;
  std::uint8_t uint8_value = 0;
  std::int16_t int16_value = 0;
  std::uint16_t uint16_value = 0;
  std::int32_t int32_value = 0;
  std::uint32_t uint32_value = 0;
  std::int64_t int64_value = 0;
  std::uint64_t uint64_value = 0;
};

// The primitive arrays of test_msgs/msg/Arrays; the message holds two sets of them (`*_values`
// and `*_values_default`).
struct ArrayValues {
  std::array<bool, 3> bool_values{};
  std::array<std::uint8_t, 3> byte_values{};
  std::array<std::uint8_t, 3> char_values{};
  std::array<float, 3> float32_values{};
  std::array<double, 3> float64_values{};
  std::array<std::int8_t, 3> int8_values{};
  std::array<std::uint8_t, 3> uint8_values{};
  std::array<std::int16_t, 3> int16_values{};
  std::array<std::uint16_t, 3> uint16_values{};
  std::array<std::int32_t, 3> int32_values{};
  std::array<std::uint32_t, 3> uint32_values{};
  std::array<std::int64_t, 3> int64_values{};
  std::array<std::uint64_t, 3> uint64_values{};
  std::array<std::string, 3> string_values{};
};

// test_msgs/msg/Arrays: ArrayValues, BasicTypes[3], Constants[3] (a message of constants only,
// serialized as the one placeholder byte rosidl gives an empty struct), Defaults[3], the
// *_default ArrayValues, and int32 alignment_check.
struct Arrays {
  ArrayValues values;
  std::array<BasicTypes, 3> basic_types_values{};
  std::array<std::uint8_t, 3> constants_values{};  // structure_needs_at_least_one_member
  std::array<BasicTypes, 3> defaults_values{};
  ArrayValues defaults;
  std::int32_t alignment_check = 0;
};

// Decoders. `what` names the message in errors (see Describe in bag_reader.h); each throws one
// InputError for a payload that is short, has a bad string or an impossible sequence length.
JointState DecodeJointState(ByteView payload, const std::string& what);
PoseStamped DecodePoseStamped(ByteView payload, const std::string& what);
Odometry DecodeOdometry(ByteView payload, const std::string& what);
TfMessage DecodeTfMessage(ByteView payload, const std::string& what);
StringMessage DecodeString(ByteView payload, const std::string& what);
BasicTypes DecodeBasicTypes(ByteView payload, const std::string& what);
Arrays DecodeArrays(ByteView payload, const std::string& what);

// Encoders (little-endian CDR unless `big_endian`).
std::vector<std::uint8_t> EncodeJointState(const JointState& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodePoseStamped(const PoseStamped& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodeOdometry(const Odometry& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodeTfMessage(const TfMessage& msg, bool big_endian = false);
std::vector<std::uint8_t> EncodeString(const StringMessage& msg, bool big_endian = false);

// Any of the types above, by ROS type name ("sensor_msgs/msg/JointState").
using RosMessage =
    std::variant<JointState, PoseStamped, Odometry, TfMessage, StringMessage, BasicTypes, Arrays>;
bool IsKnownMessageType(const std::string& type);
// Throws InputError ("unknown message type") for a type not listed above.
RosMessage DecodeMessage(const std::string& type, ByteView payload, const std::string& what);

// Field-by-field equality (round-trip tests).
bool operator==(const Header& a, const Header& b);
bool operator==(const Pose& a, const Pose& b);
bool operator==(const Transform& a, const Transform& b);
bool operator==(const TransformStamped& a, const TransformStamped& b);
bool operator==(const JointState& a, const JointState& b);
bool operator==(const PoseStamped& a, const PoseStamped& b);
bool operator==(const Odometry& a, const Odometry& b);
bool operator==(const TfMessage& a, const TfMessage& b);
bool operator==(const StringMessage& a, const StringMessage& b);
bool operator==(const BasicTypes& a, const BasicTypes& b);
bool operator==(const ArrayValues& a, const ArrayValues& b);
bool operator==(const Arrays& a, const Arrays& b);

}  // namespace fitcal::io::rosbag2
