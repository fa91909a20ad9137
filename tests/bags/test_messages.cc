// CDR decoders of the test messages (tests/bags/test_messages.h), any message by its type name,
// and field-for-field equality.

#include "tests/bags/test_messages.h"

#include <functional>
#include <map>
#include <tuple>

#include "io/rosbag2/cdr_reader.h"
#include "io/rosbag2/errors.h"

namespace fitcal::io::rosbag2 {
namespace {

BasicTypes ReadBasicTypes(CdrReader& cdr) {
  BasicTypes b;
  b.bool_value = cdr.Read<bool>();
  b.byte_value = cdr.Read<std::uint8_t>();
  b.char_value = cdr.Read<std::uint8_t>();
  b.float32_value = cdr.Read<float>();
  b.float64_value = cdr.Read<double>();
  b.int8_value = cdr.Read<std::int8_t>();
  b.uint8_value = cdr.Read<std::uint8_t>();
  b.int16_value = cdr.Read<std::int16_t>();
  b.uint16_value = cdr.Read<std::uint16_t>();
  b.int32_value = cdr.Read<std::int32_t>();
  b.uint32_value = cdr.Read<std::uint32_t>();
  b.int64_value = cdr.Read<std::int64_t>();
  b.uint64_value = cdr.Read<std::uint64_t>();
  return b;
}

template <typename T, std::size_t N>
void ReadArray(CdrReader& cdr, std::array<T, N>* out) {
  cdr.Array(out->data(), N);
}

ArrayValues ReadArrayValues(CdrReader& cdr) {
  ArrayValues a;
  ReadArray(cdr, &a.bool_values);
  ReadArray(cdr, &a.byte_values);
  ReadArray(cdr, &a.char_values);
  ReadArray(cdr, &a.float32_values);
  ReadArray(cdr, &a.float64_values);
  ReadArray(cdr, &a.int8_values);
  ReadArray(cdr, &a.uint8_values);
  ReadArray(cdr, &a.int16_values);
  ReadArray(cdr, &a.uint16_values);
  ReadArray(cdr, &a.int32_values);
  ReadArray(cdr, &a.uint32_values);
  ReadArray(cdr, &a.int64_values);
  ReadArray(cdr, &a.uint64_values);
  ReadArray(cdr, &a.string_values);
  return a;
}

}  // namespace

StringMessage DecodeString(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  return StringMessage{cdr.String()};
}

BasicTypes DecodeBasicTypes(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  return ReadBasicTypes(cdr);
}

Arrays DecodeArrays(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  Arrays msg;
  msg.values = ReadArrayValues(cdr);
  for (BasicTypes& b : msg.basic_types_values) b = ReadBasicTypes(cdr);
  ReadArray(cdr, &msg.constants_values);
  for (BasicTypes& b : msg.defaults_values) b = ReadBasicTypes(cdr);
  msg.defaults = ReadArrayValues(cdr);
  msg.alignment_check = cdr.Read<std::int32_t>();
  return msg;
}

namespace {

using Decoder = std::function<RosMessage(ByteView, const std::string&)>;

// One row per type: adding a type is one line here and one in the variant.
const std::map<std::string, Decoder>& Decoders() {
  static const std::map<std::string, Decoder> table = {
      {"sensor_msgs/msg/JointState", DecodeJointState},
      {"geometry_msgs/msg/PoseStamped", DecodePoseStamped},
      {"nav_msgs/msg/Odometry", DecodeOdometry},
      {"tf2_msgs/msg/TFMessage", DecodeTfMessage},
      {"std_msgs/msg/String", DecodeString},
      {"test_msgs/msg/BasicTypes", DecodeBasicTypes},
      {"test_msgs/msg/Arrays", DecodeArrays},
  };
  return table;
}

}  // namespace

bool IsKnownMessageType(const std::string& type) { return Decoders().count(type) != 0; }

RosMessage DecodeMessage(const std::string& type, ByteView payload, const std::string& what) {
  const auto it = Decoders().find(type);
  if (it == Decoders().end()) {
    ThrowBagError(InputErrorKind::kBadValue, what, "unknown message type " + Printable(type));
  }
  return it->second(payload, what);
}

bool operator==(const Header& a, const Header& b) {
  return a.stamp.sec == b.stamp.sec && a.stamp.nanosec == b.stamp.nanosec &&
         a.frame_id == b.frame_id;
}

namespace {
auto Tie(const Point& p) { return std::tie(p.x, p.y, p.z); }
auto Tie(const Vector3& v) { return std::tie(v.x, v.y, v.z); }
auto Tie(const Quaternion& q) { return std::tie(q.x, q.y, q.z, q.w); }
}  // namespace

bool operator==(const Pose& a, const Pose& b) {
  return Tie(a.position) == Tie(b.position) && Tie(a.orientation) == Tie(b.orientation);
}

bool operator==(const Transform& a, const Transform& b) {
  return Tie(a.translation) == Tie(b.translation) && Tie(a.rotation) == Tie(b.rotation);
}

bool operator==(const TransformStamped& a, const TransformStamped& b) {
  return a.header == b.header && a.child_frame_id == b.child_frame_id && a.transform == b.transform;
}

bool operator==(const JointState& a, const JointState& b) {
  return a.header == b.header && a.name == b.name && a.position == b.position &&
         a.velocity == b.velocity && a.effort == b.effort;
}

bool operator==(const PoseStamped& a, const PoseStamped& b) {
  return a.header == b.header && a.pose == b.pose;
}

bool operator==(const Odometry& a, const Odometry& b) {
  return a.header == b.header && a.child_frame_id == b.child_frame_id &&
         a.pose.pose == b.pose.pose && a.pose.covariance == b.pose.covariance &&
         Tie(a.twist.twist.linear) == Tie(b.twist.twist.linear) &&
         Tie(a.twist.twist.angular) == Tie(b.twist.twist.angular) &&
         a.twist.covariance == b.twist.covariance;
}

bool operator==(const TfMessage& a, const TfMessage& b) { return a.transforms == b.transforms; }
bool operator==(const StringMessage& a, const StringMessage& b) { return a.data == b.data; }

namespace {
auto Tie(const BasicTypes& t) {
  return std::tie(t.bool_value, t.byte_value, t.char_value, t.float32_value, t.float64_value,
                  t.int8_value, t.uint8_value, t.int16_value, t.uint16_value, t.int32_value,
                  t.uint32_value, t.int64_value, t.uint64_value);
}
auto Tie(const ArrayValues& v) {
  return std::tie(v.bool_values, v.byte_values, v.char_values, v.float32_values, v.float64_values,
                  v.int8_values, v.uint8_values, v.int16_values, v.uint16_values, v.int32_values,
                  v.uint32_values, v.int64_values, v.uint64_values, v.string_values);
}
}  // namespace

bool operator==(const BasicTypes& a, const BasicTypes& b) { return Tie(a) == Tie(b); }
bool operator==(const ArrayValues& a, const ArrayValues& b) { return Tie(a) == Tie(b); }

bool operator==(const Arrays& a, const Arrays& b) {
  return a.values == b.values && a.basic_types_values == b.basic_types_values &&
         a.constants_values == b.constants_values && a.defaults_values == b.defaults_values &&
         a.defaults == b.defaults && a.alignment_check == b.alignment_check;
}

}  // namespace fitcal::io::rosbag2
