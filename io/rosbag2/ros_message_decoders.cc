// CDR decoders of the message types in ros_messages.h: fields in .msg order, nested messages
// inline (CDR has no per-struct framing in XCDR1), so each helper reads one nested type. The
// helpers fill a message as a braced list, whose elements are evaluated in order ([dcl.init.list]):
// the fields are read in the order they are declared, which is their .msg order.

#include "io/rosbag2/cdr_reader.h"
#include "io/rosbag2/ros_messages.h"

namespace fitcal::io::rosbag2 {
namespace {

// Smallest serialized TransformStamped: stamp 8, frame_id and child_frame_id lengths 4 + 4,
// then 7 doubles; used to bound a transforms[] length before allocating.
constexpr std::size_t kMinTransformStampedBytes = 8 + 4 + 4 + 7 * 8;

Header ReadHeader(CdrReader& cdr) {
  return {{cdr.Read<std::int32_t>(), cdr.Read<std::uint32_t>()}, cdr.String()};
}

// geometry_msgs Point and Vector3: three float64 x, y, z.
template <typename Xyz>
Xyz ReadXyz(CdrReader& cdr) {
  return {cdr.Read<double>(), cdr.Read<double>(), cdr.Read<double>()};
}

Quaternion ReadQuaternion(CdrReader& cdr) {
  return {cdr.Read<double>(), cdr.Read<double>(), cdr.Read<double>(), cdr.Read<double>()};
}

Pose ReadPose(CdrReader& cdr) { return {ReadXyz<Point>(cdr), ReadQuaternion(cdr)}; }

TransformStamped ReadTransformStamped(CdrReader& cdr) {
  return {ReadHeader(cdr), cdr.String(), {ReadXyz<Vector3>(cdr), ReadQuaternion(cdr)}};
}

}  // namespace

JointState DecodeJointState(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  return {ReadHeader(cdr), cdr.Sequence<std::string>(), cdr.Sequence<double>(),
          cdr.Sequence<double>(), cdr.Sequence<double>()};
}

PoseStamped DecodePoseStamped(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  return {ReadHeader(cdr), ReadPose(cdr)};
}

Odometry DecodeOdometry(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  Odometry msg;
  msg.header = ReadHeader(cdr);
  msg.child_frame_id = cdr.String();
  msg.pose.pose = ReadPose(cdr);
  cdr.Array(msg.pose.covariance.data(), msg.pose.covariance.size());
  msg.twist.twist.linear = ReadXyz<Vector3>(cdr);
  msg.twist.twist.angular = ReadXyz<Vector3>(cdr);
  cdr.Array(msg.twist.covariance.data(), msg.twist.covariance.size());
  return msg;
}

TfMessage DecodeTfMessage(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  TfMessage msg;
  const std::uint32_t count = cdr.SequenceLength(kMinTransformStampedBytes, 4);
  msg.transforms.reserve(count);
  for (std::uint32_t i = 0; i < count; ++i) msg.transforms.push_back(ReadTransformStamped(cdr));
  return msg;
}

}  // namespace fitcal::io::rosbag2
