// CDR encoders of the message types in ros_messages.h, field for field the mirror of
// ros_message_decoders.cc.

#include "tests/bags/cdr_writer.h"
#include "tests/bags/ros_message_encoders.h"

namespace fitcal::io::rosbag2 {
namespace {

void WriteHeader(CdrWriter& cdr, const Header& header) {
  cdr.Int32(header.stamp.sec);
  cdr.Uint32(header.stamp.nanosec);
  cdr.String(header.frame_id);
}

void WriteXyz(CdrWriter& cdr, double x, double y, double z) {
  cdr.Float64(x);
  cdr.Float64(y);
  cdr.Float64(z);
}

void WriteQuaternion(CdrWriter& cdr, const Quaternion& q) {
  WriteXyz(cdr, q.x, q.y, q.z);
  cdr.Float64(q.w);
}

void WritePose(CdrWriter& cdr, const Pose& pose) {
  WriteXyz(cdr, pose.position.x, pose.position.y, pose.position.z);
  WriteQuaternion(cdr, pose.orientation);
}

}  // namespace

std::vector<std::uint8_t> EncodeJointState(const JointState& msg, bool big_endian) {
  CdrWriter cdr(big_endian);
  WriteHeader(cdr, msg.header);
  cdr.Sequence(msg.name);
  cdr.Sequence(msg.position);
  cdr.Sequence(msg.velocity);
  cdr.Sequence(msg.effort);
  return cdr.Bytes();
}

std::vector<std::uint8_t> EncodePoseStamped(const PoseStamped& msg, bool big_endian) {
  CdrWriter cdr(big_endian);
  WriteHeader(cdr, msg.header);
  WritePose(cdr, msg.pose);
  return cdr.Bytes();
}

std::vector<std::uint8_t> EncodeOdometry(const Odometry& msg, bool big_endian) {
  CdrWriter cdr(big_endian);
  WriteHeader(cdr, msg.header);
  cdr.String(msg.child_frame_id);
  WritePose(cdr, msg.pose.pose);
  cdr.Array(msg.pose.covariance.data(), msg.pose.covariance.size());
  const Twist& twist = msg.twist.twist;
  WriteXyz(cdr, twist.linear.x, twist.linear.y, twist.linear.z);
  WriteXyz(cdr, twist.angular.x, twist.angular.y, twist.angular.z);
  cdr.Array(msg.twist.covariance.data(), msg.twist.covariance.size());
  return cdr.Bytes();
}

std::vector<std::uint8_t> EncodeTfMessage(const TfMessage& msg, bool big_endian) {
  CdrWriter cdr(big_endian);
  cdr.Uint32(static_cast<std::uint32_t>(msg.transforms.size()));
  for (const TransformStamped& t : msg.transforms) {
    WriteHeader(cdr, t.header);
    cdr.String(t.child_frame_id);
    const Vector3& v = t.transform.translation;
    WriteXyz(cdr, v.x, v.y, v.z);
    WriteQuaternion(cdr, t.transform.rotation);
  }
  return cdr.Bytes();
}

std::vector<std::uint8_t> EncodeString(const StringMessage& msg, bool big_endian) {
  CdrWriter cdr(big_endian);
  cdr.String(msg.data);
  return cdr.Bytes();
}

}  // namespace fitcal::io::rosbag2
