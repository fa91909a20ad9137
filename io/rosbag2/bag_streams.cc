#include "io/rosbag2/bag_streams.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "io/input_error.h"
#include "io/rosbag2/bag_reader.h"
#include "io/rosbag2/errors.h"
#include "io/rosbag2/ros_messages.h"

namespace fitcal::io::rosbag2 {
namespace {

namespace fs = std::filesystem;

constexpr const char* kJointStateType = "sensor_msgs/msg/JointState";
constexpr const char* kPoseStampedType = "geometry_msgs/msg/PoseStamped";
constexpr const char* kOdometryType = "nav_msgs/msg/Odometry";
constexpr const char* kTfType = "tf2_msgs/msg/TFMessage";

std::string Seconds(std::int64_t t_ns) {
  char text[48];
  std::snprintf(text, sizeof text, "%.9f s", static_cast<double>(t_ns) * 1e-9);
  return text;
}

// tf2 ignores a leading '/' in frame ids (ROS 1 habit); so does the matching here.
std::string StripSlash(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

const TopicInfo& RequireTopic(const BagReader& bag, const std::string& bag_path,
                              const std::string& name, const std::string& role) {
  const TopicInfo* topic = bag.FindTopic(name);
  if (topic == nullptr) {
    std::string have;
    for (const TopicInfo& t : bag.topics()) have += (have.empty() ? "" : ", ") + t.name;
    ThrowBagError(InputErrorKind::kMissingKey, bag_path,
                  role + " topic " + Printable(name) +
                      " is not in the bag (topics: " + Printable(have, 160) + ")");
  }
  return *topic;
}

// Appends the stamp of a stream sample after checking that it increases strictly.
void PushStamp(std::vector<std::int64_t>* stamps, std::int64_t t_ns, const BagMessage& m,
               StampSource source) {
  if (!stamps->empty() && t_ns <= stamps->back()) {
    ThrowBagError(
        InputErrorKind::kNonIncreasingTime, Describe(m),
        std::string(source == StampSource::kHeader ? "header stamp " : "time ") + Seconds(t_ns) +
            " is not after the previous one (" + Seconds(stamps->back()) + ")" +
            (source == StampSource::kHeader ? "; --stamp recorded uses the recording time" : ""));
  }
  stamps->push_back(t_ns);
}

class JointCollector {
 public:
  JointCollector(const BagStreamRequest& request, JointStream* out)
      : request_(request), out_(out) {}

  void Add(const BagMessage& m) {
    const JointState js = DecodeJointState(m.payload, Describe(m));
    if (js.name != names_) MapNames(js, m);
    const std::vector<double>& field = out_->positions ? js.position : js.velocity;
    if (field.size() != js.name.size()) {
      ThrowBagError(InputErrorKind::kWrongColumnCount, Describe(m),
                    std::string("has ") + std::to_string(field.size()) +
                        (out_->positions ? " positions" : " velocities") + " for " +
                        std::to_string(js.name.size()) +
                        " joint names (earlier messages had one "
                        "per joint)");
    }
    for (std::size_t j = 0; j < index_.size(); ++j) {
      const double v = field[index_[j]];
      if (!std::isfinite(v)) {
        ThrowBagError(InputErrorKind::kNonFinite, Describe(m),
                      "joint " + Printable(request_.joints[j]) + " is not finite");
      }
      out_->values.push_back(v);
    }
    const std::int64_t t_ns =
        request_.stamp == StampSource::kHeader ? js.header.stamp.ToNanoseconds() : m.time_ns;
    PushStamp(&out_->t_ns, t_ns, m, request_.stamp);
  }

 private:
  // A message whose name list differs from the previous one: find each requested joint again
  // (joint_state_broadcaster keeps the order fixed, so this runs once per bag in practice).
  void MapNames(const JointState& js, const BagMessage& m) {
    index_.assign(request_.joints.size(), 0);
    for (std::size_t j = 0; j < request_.joints.size(); ++j) {
      std::size_t k = 0;
      while (k < js.name.size() && js.name[k] != request_.joints[j]) ++k;
      if (k == js.name.size()) {
        std::string have;
        for (const std::string& n : js.name) have += (have.empty() ? "" : ", ") + n;
        ThrowBagError(InputErrorKind::kMissingKey, Describe(m),
                      "joint " + Printable(request_.joints[j]) + " is not in the message (names: " +
                          Printable(have, 160) + "); --joints names them in the robot's order");
      }
      index_[j] = k;
    }
    if (names_.empty()) ChooseField(js, m);
    names_ = js.name;
  }

  // Positions (cumulative angles: exact wheel-angle advance per interval) when the first message
  // has one per joint, else velocities; an angle channel needs positions.
  void ChooseField(const JointState& js, const BagMessage& m) {
    out_->positions = !js.position.empty() && js.position.size() == js.name.size();
    if (!out_->positions && js.velocity.size() != js.name.size()) {
      ThrowBagError(InputErrorKind::kWrongColumnCount, Describe(m),
                    "has neither a position nor a velocity for every joint");
    }
    for (std::size_t j = 0; j < request_.joints.size(); ++j) {
      if (!out_->positions && request_.needs_position[j]) {
        ThrowBagError(InputErrorKind::kMissingKey, Describe(m),
                      "joint " + Printable(request_.joints[j]) +
                          " is an angle (e.g. steering) and needs positions; the message has "
                          "velocities only");
      }
    }
  }

  const BagStreamRequest& request_;
  JointStream* out_;
  std::vector<std::string> names_;
  std::vector<std::size_t> index_;
};

Pose2d PlanarPose(const Point& p, const Quaternion& q) {
  return {p.x, p.y, YawOfQuaternion(q.x, q.y, q.z, q.w)};
}

class PoseCollector {
 public:
  PoseCollector(const BagStreamRequest& request, const std::string& type, PoseStream* out)
      : request_(request), type_(type), out_(out) {}

  void Add(const BagMessage& m) {
    if (type_ == kPoseStampedType) {
      const PoseStamped p = DecodePoseStamped(m.payload, Describe(m));
      Push(m, p.header, PlanarPose(p.pose.position, p.pose.orientation));
    } else if (type_ == kOdometryType) {
      const Odometry o = DecodeOdometry(m.payload, Describe(m));
      Push(m, o.header, PlanarPose(o.pose.pose.position, o.pose.pose.orientation));
    } else {
      for (const TransformStamped& t : DecodeTfMessage(m.payload, Describe(m)).transforms) {
        if (StripSlash(t.header.frame_id) != request_.parent_frame ||
            StripSlash(t.child_frame_id) != request_.child_frame) {
          continue;
        }
        const Vector3& v = t.transform.translation;
        Push(m, t.header, PlanarPose(Point{v.x, v.y, v.z}, t.transform.rotation));
      }
    }
  }

 private:
  void Push(const BagMessage& m, const Header& header, Pose2d pose) {
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
      ThrowBagError(InputErrorKind::kNonFinite, Describe(m), "pose is not finite");
    }
    // Unwrap: the yaw moves by less than pi between two samples of any real ground truth.
    if (!out_->world_T_robot.empty()) {
      const double previous = out_->world_T_robot.back().theta;
      pose.theta = previous + WrapAngle(pose.theta - previous);
    }
    PushStamp(&out_->t_ns,
              request_.stamp == StampSource::kHeader ? header.stamp.ToNanoseconds() : m.time_ns, m,
              request_.stamp);
    out_->world_T_robot.push_back(pose);
  }

  const BagStreamRequest& request_;
  std::string type_;
  PoseStream* out_;
};

void CheckTypes(const BagReader& bag, const std::string& bag_path, const BagStreamRequest& r) {
  const TopicInfo& joints = RequireTopic(bag, bag_path, r.joint_topic, "encoder");
  if (joints.type != kJointStateType) {
    ThrowBagError(InputErrorKind::kBadValue, bag_path,
                  "encoder topic " + Printable(r.joint_topic) + " has type " +
                      Printable(joints.type) + ", not " + kJointStateType);
  }
  const TopicInfo& pose = RequireTopic(bag, bag_path, r.pose_topic, "ground-truth");
  const bool tf = pose.type == kTfType;
  if (!tf && pose.type != kPoseStampedType && pose.type != kOdometryType) {
    ThrowBagError(InputErrorKind::kBadValue, bag_path,
                  "ground-truth topic " + Printable(r.pose_topic) + " has type " +
                      Printable(pose.type) + "; fitcal reads " + kPoseStampedType + ", " +
                      kOdometryType + " or " + kTfType);
  }
  if (tf && (r.parent_frame.empty() || r.child_frame.empty())) {
    ThrowBagError(InputErrorKind::kMissingKey, bag_path,
                  "ground-truth topic " + Printable(r.pose_topic) +
                      " is a TFMessage: name the transform with --ground-truth-frames "
                      "parent:child (e.g. world:base_link)");
  }
}

}  // namespace

double YawOfQuaternion(double x, double y, double z, double w) {
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

BagStreams ReadBagStreams(const std::string& bag_path, const BagStreamRequest& request) {
  BagReader bag(bag_path);
  CheckTypes(bag, bag_path, request);
  BagStreams out;
  out.bag = bag_path;
  out.start_time_ns = bag.start_time_ns();
  for (const std::string& f : bag.files()) {
    std::error_code ec;
    const auto size = fs::file_size(f, ec);
    if (!ec) out.bytes += size;
  }
  const TopicInfo* joint_topic = bag.FindTopic(request.joint_topic);
  const TopicInfo* pose_topic = bag.FindTopic(request.pose_topic);
  out.pose_type = pose_topic->type;
  out.joints.t_ns.reserve(joint_topic->message_count);
  out.joints.values.reserve(joint_topic->message_count * request.joints.size());
  JointCollector joints(request, &out.joints);
  PoseCollector poses(request, pose_topic->type, &out.poses);
  BagMessage m;
  while (bag.ReadNext(&m)) {
    if (m.topic == joint_topic) {
      joints.Add(m);
    } else if (m.topic == pose_topic) {
      poses.Add(m);
    }
  }
  if (out.joints.t_ns.size() < 2) {
    ThrowBagError(InputErrorKind::kTooFewSamples, bag_path,
                  "encoder topic " + Printable(request.joint_topic) + " has " +
                      std::to_string(out.joints.t_ns.size()) + " message(s); at least 2 needed");
  }
  if (out.poses.t_ns.empty()) {
    ThrowBagError(InputErrorKind::kTooFewSamples, bag_path,
                  "ground-truth topic " + Printable(request.pose_topic) + " holds no pose" +
                      (out.pose_type == kTfType ? " of the transform " + request.parent_frame +
                                                      " -> " + request.child_frame
                                                : std::string()));
  }
  return out;
}

}  // namespace fitcal::io::rosbag2
