#pragma once
// The messages only the tests read or write: std_msgs/msg/String and, in the recorder's own test
// bags (../shared/data/rosbag2), test_msgs/msg/BasicTypes and test_msgs/msg/Arrays
// (ros2/rcl_interfaces; the exact text is stored in the bags themselves, in the sqlite3
// message_definitions table and the MCAP Schema records); any message by type name; equality for
// round trips. The CDR reader they decode with is the product's (io/rosbag2/cdr_reader.h).

#include <array>
#include <cstdint>
#include <string>
#include <variant>

#include "io/rosbag2/ros_messages.h"

namespace fitcal::io::rosbag2 {

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

// Decoders, as those of io/rosbag2/ros_messages.h.
StringMessage DecodeString(ByteView payload, const std::string& what);
BasicTypes DecodeBasicTypes(ByteView payload, const std::string& what);
Arrays DecodeArrays(ByteView payload, const std::string& what);

// Any of these types and those of io/rosbag2/ros_messages.h, by ROS type name
// ("sensor_msgs/msg/JointState").
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
