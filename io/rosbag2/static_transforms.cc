#include "io/rosbag2/static_transforms.h"
#include "odometry/text_format.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

namespace fitcal::io::rosbag2 {
namespace {

std::string Frame(const std::string& id) { return !id.empty() && id[0] == '/' ? id.substr(1) : id; }

struct Edge {
  std::string parent;
  Eigen::Isometry3d parent_T_child;
};

// A tree deeper than this is a cycle (a bag that publishes a -> b and b -> a).
constexpr std::size_t kMaxDepth = 64;

// A frame within a micrometre and a microradian of the base in the plane (base_footprint under
// base_link, a z offset only) is the base: fitting a mount there adds three parameters for none.
constexpr double kOnTheBaseM = 1e-6;
constexpr double kOnTheBaseRad = 1e-6;

// The frames from `frame` up to its root, and root_T_frame.
std::vector<std::string> Ancestors(const std::map<std::string, Edge>& parent_of,
                                   const std::string& frame, Eigen::Isometry3d* root_T_frame) {
  std::vector<std::string> up = {frame};
  *root_T_frame = Eigen::Isometry3d::Identity();
  for (auto it = parent_of.find(frame); it != parent_of.end() && up.size() < kMaxDepth;
       it = parent_of.find(it->second.parent)) {
    *root_T_frame = it->second.parent_T_child * *root_T_frame;
    up.push_back(it->second.parent);
  }
  return up;
}

// A composed transform's rounding (1e-16) shown as 0, not as -2.77556e-17.
std::string Number(double v) { return MessageNumber(std::abs(v) < 5e-13 ? 0.0 : v); }

}  // namespace

StaticMount StaticTransformBetween(const std::vector<TransformStamped>& transforms,
                                   const std::string& base_frame, const std::string& child_frame) {
  std::map<std::string, Edge> parent_of;
  for (const TransformStamped& t : transforms) {
    const Vector3& v = t.transform.translation;
    const Quaternion& q = t.transform.rotation;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(v.x, v.y, v.z);
    parent_of[Frame(t.child_frame_id)] = {Frame(t.header.frame_id), T};
  }
  Eigen::Isometry3d root_T_base, root_T_child;
  const std::vector<std::string> from_base = Ancestors(parent_of, Frame(base_frame), &root_T_base);
  const std::vector<std::string> from_child =
      Ancestors(parent_of, Frame(child_frame), &root_T_child);
  StaticMount out;
  if (from_base.back() != from_child.back()) return out;  // two trees (or a cycle)
  // The chain through the lowest common ancestor.
  std::size_t up = 0;
  while (std::find(from_child.begin(), from_child.end(), from_base[up]) == from_child.end()) ++up;
  const auto down = std::find(from_child.begin(), from_child.end(), from_base[up]);
  for (std::size_t i = 0; i <= up; ++i) out.chain += (i ? " -> " : "") + from_base[i];
  for (auto it = std::make_reverse_iterator(down); it != from_child.rend(); ++it) {
    out.chain += " -> " + *it;
  }
  const Eigen::Isometry3d base_T_child = root_T_base.inverse() * root_T_child;
  const Eigen::Quaterniond q(base_T_child.linear());
  out.base_T_sensor = Pose2d{base_T_child.translation().x(), base_T_child.translation().y(),
                             YawOfQuaternion(q.x(), q.y(), q.z(), q.w())};
  return out;
}

GroundTruthMountFromBag MountFromTfStatic(const BagStreams& streams, const std::string& topic,
                                          const std::string& base_frame) {
  GroundTruthMountFromBag out;
  const std::string frame = Frame(streams.pose_frame);
  if (frame == Frame(base_frame)) return out;  // the ground truth tracks the base itself
  if (frame.empty()) {
    if (streams.has_tf_static) {
      out.note = "ground truth " + topic + " (" + streams.pose_type +
                 ") names no frame of its own: /tf_static not used for ground_truth_frame "
                 "(--ground-truth-frames <parent>:<frame> names the frame it tracks)";
    }
    return out;
  }
  const std::string what =
      "ground truth " + topic + " tracks frame '" + frame + "', not '" + Frame(base_frame) + "'";
  if (!streams.has_tf_static) {
    out.note = what +
               ": the bag has no /tf_static, so no ground_truth_frame is written (declare "
               "its pose in the robot YAML: ground_truth_frame: {x_m, y_m, yaw_deg})";
    return out;
  }
  const StaticMount mount = StaticTransformBetween(streams.static_transforms, base_frame, frame);
  if (!mount.base_T_sensor) {
    out.note = what +
               ": /tf_static has no transform between them, so no ground_truth_frame is "
               "written (declare its pose in the robot YAML, or --base-frame names the "
               "robot's base frame)";
    return out;
  }
  const Pose2d& p = *mount.base_T_sensor;
  if (std::hypot(p.x, p.y) < kOnTheBaseM && std::abs(p.theta) < kOnTheBaseRad) {
    out.note = what + ", which /tf_static (" + mount.chain +
               ") puts on it in the plane: the ground truth tracks the base, no ground_truth_frame "
               "written";
    return out;
  }
  out.base_T_sensor = p;
  out.note = what + ": ground_truth_frame: {x_m: " + Number(p.x) + ", y_m: " + Number(p.y) +
             ", yaw_deg: " + Number(p.theta * 180.0 / M_PI) + "} from /tf_static (" + mount.chain +
             ") written to the robot YAML as the fit's nominal";
  return out;
}

}  // namespace fitcal::io::rosbag2
