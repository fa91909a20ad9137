// CDR decoders of the message types in ros_messages.h: fields in .msg order, nested messages
// inline (CDR has no per-struct framing in XCDR1), so each helper reads one nested type.

#include "io/rosbag2/cdr_reader.h"
#include "io/rosbag2/errors.h"
#include "io/rosbag2/ros_messages.h"

namespace fitcal::io::rosbag2 {
namespace {

// Smallest serialized TransformStamped: stamp 8, frame_id and child_frame_id lengths 4 + 4,
// then 7 doubles; used to bound a transforms[] length before allocating.
constexpr std::size_t kMinTransformStampedBytes = 8 + 4 + 4 + 7 * 8;

Header ReadHeader(CdrReader& cdr) {
  Header header;
  header.stamp.sec = cdr.Int32();
  header.stamp.nanosec = cdr.Uint32();
  header.frame_id = cdr.String();
  return header;
}

// geometry_msgs Point and Vector3: three float64 x, y, z.
template <typename Xyz>
Xyz ReadXyz(CdrReader& cdr) {
  Xyz v;
  v.x = cdr.Float64();
  v.y = cdr.Float64();
  v.z = cdr.Float64();
  return v;
}

Quaternion ReadQuaternion(CdrReader& cdr) {
  Quaternion q;
  q.x = cdr.Float64();
  q.y = cdr.Float64();
  q.z = cdr.Float64();
  q.w = cdr.Float64();
  return q;
}

Pose ReadPose(CdrReader& cdr) {
  Pose pose;
  pose.position = ReadXyz<Point>(cdr);
  pose.orientation = ReadQuaternion(cdr);
  return pose;
}

TransformStamped ReadTransformStamped(CdrReader& cdr) {
  TransformStamped t;
  t.header = ReadHeader(cdr);
  t.child_frame_id = cdr.String();
  t.transform.translation = ReadXyz<Vector3>(cdr);
  t.transform.rotation = ReadQuaternion(cdr);
  return t;
}

}  // namespace

JointState DecodeJointState(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  JointState msg;
  msg.header = ReadHeader(cdr);
  msg.name = cdr.Sequence<std::string>();
  msg.position = cdr.Sequence<double>();
  msg.velocity = cdr.Sequence<double>();
  msg.effort = cdr.Sequence<double>();
  return msg;
}

PoseStamped DecodePoseStamped(ByteView payload, const std::string& what) {
  CdrReader cdr(payload, what);
  PoseStamped msg;
  msg.header = ReadHeader(cdr);
  msg.pose = ReadPose(cdr);
  return msg;
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
