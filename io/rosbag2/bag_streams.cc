#include "io/rosbag2/bag_streams.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "io/input_error.h"
#include "io/rosbag2/bag_metadata.h"
#include "io/rosbag2/bag_reader.h"
#include "io/rosbag2/errors.h"
#include "io/text_file.h"
#include "odometry/text_format.h"

namespace fitcal::io::rosbag2 {
namespace {

namespace fs = std::filesystem;

constexpr const char* kJointStateType = "sensor_msgs/msg/JointState";
constexpr const char* kPoseStampedType = "geometry_msgs/msg/PoseStamped";
constexpr const char* kOdometryType = "nav_msgs/msg/Odometry";
constexpr const char* kTfType = "tf2_msgs/msg/TFMessage";
constexpr const char* kTfStaticTopic = "/tf_static";

std::string Seconds(std::int64_t t_ns) {
  return StrFormat("%.9f s", static_cast<double>(t_ns) * 1e-9);
}

// tf2 ignores a leading '/' in frame ids (ROS 1 habit); so does the matching here.
std::string StripSlash(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

const TopicInfo& RequireTopic(const BagReader& bag, const std::string& bag_path,
                              const std::string& name, const std::string& role) {
  const TopicInfo* topic = bag.FindTopic(name);
  if (topic == nullptr) {
    const std::string have =
        Joined(bag.topics(), ", ", [](const TopicInfo& t) { return Printable(t.name); });
    ThrowBagError(InputErrorKind::kMissingKey, bag_path,
                  role + " topic " + Printable(name) + " is not in the bag (topics: " + have + ")");
  }
  return *topic;
}

// Appends the stamp of a stream sample, remembering the first one that does not increase
// strictly: ReadBagStreams decides at the end whether that is bad input (it is, unless the
// recording clock stepped back and the header stamps put the messages in order again).
class StampOrder {
 public:
  void Push(std::vector<std::int64_t>* stamps, std::int64_t t_ns, const BagMessage& m,
            StampSource source) {
    if (!first_file_.empty() || stamps->empty() || t_ns > stamps->back()) {
      stamps->push_back(t_ns);
      return;
    }
    first_file_ = Describe(m);
    first_what_ =
        std::string(source == StampSource::kHeader ? "header stamp " : "time ") + Seconds(t_ns) +
        " is not after the previous one (" + Seconds(stamps->back()) + ")" +
        (source == StampSource::kHeader ? "; --stamp recorded uses the recording time" : "");
    stamps->push_back(t_ns);
  }
  bool violated() const { return !first_file_.empty(); }
  void ThrowIfViolated() const {
    if (violated()) ThrowBagError(InputErrorKind::kNonIncreasingTime, first_file_, first_what_);
  }

 private:
  std::string first_file_, first_what_;
};

bool StrictlyIncreasing(const std::vector<std::int64_t>& t) {
  return std::adjacent_find(t.begin(), t.end(), [](std::int64_t a, std::int64_t b) {
           return b <= a;
         }) == t.end();
}

// The order of `t` by value (stable).
std::vector<std::size_t> OrderByStamp(const std::vector<std::int64_t>& t) {
  std::vector<std::size_t> order(t.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return t[a] < t[b]; });
  return order;
}

void SortByStamp(JointStream* s, std::size_t joints) {
  const std::vector<std::size_t> order = OrderByStamp(s->t_ns);
  std::vector<std::int64_t> t;
  std::vector<double> v;
  for (std::size_t i : order) {
    t.push_back(s->t_ns[i]);
    v.insert(v.end(), s->values.begin() + static_cast<std::ptrdiff_t>(i * joints),
             s->values.begin() + static_cast<std::ptrdiff_t>((i + 1) * joints));
  }
  s->t_ns = std::move(t);
  s->values = std::move(v);
}

void SortByStamp(PoseStream* s) {
  const std::vector<std::size_t> order = OrderByStamp(s->t_ns);
  std::vector<std::int64_t> t;
  std::vector<Pose2d> poses;
  for (std::size_t i : order) {
    t.push_back(s->t_ns[i]);
    poses.push_back(s->world_T_robot[i]);
    if (poses.size() > 1) {  // unwrapped again in the new order
      const double previous = poses[poses.size() - 2].theta;
      poses.back().theta = previous + WrapAngle(poses.back().theta - previous);
    }
  }
  s->t_ns = std::move(t);
  s->world_T_robot = std::move(poses);
}

class JointCollector {
 public:
  JointCollector(const BagStreamRequest& request, JointStream* out)
      : request_(request), out_(out) {}

  void Add(const BagMessage& m) {
    const JointState js = DecodeJointState(m.payload, Describe(m));
    if (js.name != names_ && !MapNames(js, m)) {
      // Another node's joints on the same topic (a gripper, a pan-tilt head publishing its own
      // JointState): normal in ROS 2, skipped. Its name list is not remembered, so the robot's
      // next message maps its names again.
      ++skipped_;
      return;
    }
    const std::vector<double>& field = out_->positions ? js.position : js.velocity;
    if (field.size() != js.name.size()) {
      ThrowBagError(InputErrorKind::kWrongColumnCount, Describe(m),
                    std::string("has ") + std::to_string(field.size()) +
                        (out_->positions ? " positions" : " velocities") + " for " +
                        std::to_string(js.name.size()) +
                        " joint names (earlier messages had one per joint)");
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
    order.Push(&out_->t_ns, t_ns, m, request_.stamp);
  }

  StampOrder order;

  // After the last message: a topic on which no message carried the robot's joints.
  void Finish(const std::string& bag_path) const {
    if (!out_->t_ns.empty() || skipped_ == 0) return;
    ThrowBagError(InputErrorKind::kMissingKey, bag_path,
                  "joint " + Printable(request_.joints[0]) +
                      " is not in the message (none of the " + std::to_string(skipped_) +
                      " messages on " + Printable(request_.joint_topic) +
                      " carries the robot's joints; names: " +
                      Printable(Joined(first_skipped_names_, ", "), 160) +
                      "); --joints names them in the robot's order");
  }

 private:
  // A message whose name list differs from the previous one: find each requested joint again
  // (joint_state_broadcaster keeps the order fixed, so this runs once per bag in practice).
  // False for a message that carries none of the requested joints (another node's); a message
  // that carries some but not all of them is bad input.
  bool MapNames(const JointState& js, const BagMessage& m) {
    std::size_t carried = 0;
    for (const std::string& joint : request_.joints) {
      carried += std::find(js.name.begin(), js.name.end(), joint) != js.name.end();
    }
    if (carried == 0) {
      if (skipped_ == 0) first_skipped_names_ = js.name;
      names_.clear();
      return false;
    }
    index_.assign(request_.joints.size(), 0);
    for (std::size_t j = 0; j < request_.joints.size(); ++j) {
      std::size_t k = 0;
      while (k < js.name.size() && js.name[k] != request_.joints[j]) ++k;
      if (k == js.name.size()) {
        ThrowBagError(InputErrorKind::kMissingKey, Describe(m),
                      "joint " + Printable(request_.joints[j]) + " is not in the message (names: " +
                          Printable(Joined(js.name, ", "), 160) +
                          "); --joints names them in the robot's order");
      }
      index_[j] = k;
    }
    if (!field_chosen_) ChooseField(js, m);
    field_chosen_ = true;
    names_ = js.name;
    return true;
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
  bool field_chosen_ = false;
  std::size_t skipped_ = 0;
  std::vector<std::string> first_skipped_names_;
};

// A rotation is a unit quaternion. A zero one (an uninitialised message, a tracker that lost the
// body) or one far from unit length (a corrupted field, a hand-written message) has no yaw:
// atan2 of it returns a number all the same (0 for the zero quaternion), so it is refused, with
// the topic, the time and the norm. Tolerance 1e-3 on the norm: float32 trackers normalise to
// ~1e-7, and a quaternion off by 1e-3 moves the yaw by at most ~1e-3 rad.
constexpr double kUnitQuaternionTolerance = 1e-3;

Pose2d PlanarPose(const Point& p, const Quaternion& q, const Header& header, const BagMessage& m) {
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance)) {
    ThrowBagError(InputErrorKind::kBadValue, Describe(m),
                  StrFormat("orientation (x %.6g, y %.6g, z %.6g, w %.6g) is %s quaternion (norm "
                            "%.6g), not a rotation; header stamp ",
                            q.x, q.y, q.z, q.w, norm == 0.0 ? "a zero" : "not a unit", norm) +
                      Seconds(header.stamp.ToNanoseconds()));
  }
  return {p.x, p.y, YawOfQuaternion(q.x, q.y, q.z, q.w)};
}

class PoseCollector {
 public:
  PoseCollector(const BagStreamRequest& request, const std::string& type, PoseStream* out)
      : request_(request), type_(type), out_(out) {}

  void Add(const BagMessage& m) {
    if (type_ == kPoseStampedType) {
      const PoseStamped p = DecodePoseStamped(m.payload, Describe(m));
      KeepFrames(m, p.header.frame_id, "");
      Push(m, p.header, PlanarPose(p.pose.position, p.pose.orientation, p.header, m));
    } else if (type_ == kOdometryType) {
      const Odometry o = DecodeOdometry(m.payload, Describe(m));
      KeepFrames(m, o.header.frame_id, o.child_frame_id);
      Push(m, o.header, PlanarPose(o.pose.pose.position, o.pose.pose.orientation, o.header, m));
    } else {
      for (const TransformStamped& t : DecodeTfMessage(m.payload, Describe(m)).transforms) {
        if (StripSlash(t.header.frame_id) != request_.parent_frame ||
            StripSlash(t.child_frame_id) != request_.child_frame) {
          continue;
        }
        const Vector3& v = t.transform.translation;
        Push(m, t.header, PlanarPose(Point{v.x, v.y, v.z}, t.transform.rotation, t.header, m));
      }
    }
  }

 private:
  // One frame and one child frame for the whole topic, those of its first message. A ground truth
  // whose frame changes mid-bag (a localisation restarted in `map` after `world`, an Odometry's
  // child switched to another sensor) holds poses of two frames on one track, which no odometry
  // follows; refused naming the message.
  void KeepFrames(const BagMessage& m, const std::string& frame, const std::string& child) {
    if (out_->t_ns.empty()) {
      frame_ = StripSlash(frame);
      child_frame = StripSlash(child);
      return;
    }
    const auto same = [&m](const char* field, const std::string& first, const std::string& now) {
      if (now == first) return;
      ThrowBagError(InputErrorKind::kBadValue, Describe(m),
                    std::string(field) + " " + Printable(now) + " differs from " +
                        Printable(first) + " of the topic's first message: poses in two frames "
                        "are not one ground truth");
    };
    same("header.frame_id", frame_, StripSlash(frame));
    same("child_frame_id", child_frame, StripSlash(child));
  }

  void Push(const BagMessage& m, const Header& header, Pose2d pose) {
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
      ThrowBagError(InputErrorKind::kNonFinite, Describe(m), "pose is not finite");
    }
    // Unwrap: the yaw moves by less than pi between two samples of any real ground truth.
    if (!out_->world_T_robot.empty()) {
      const double previous = out_->world_T_robot.back().theta;
      pose.theta = previous + WrapAngle(pose.theta - previous);
    }
    order.Push(&out_->t_ns,
               request_.stamp == StampSource::kHeader ? header.stamp.ToNanoseconds() : m.time_ns,
               m, request_.stamp);
    out_->world_T_robot.push_back(pose);
  }

 public:
  StampOrder order;
  std::string child_frame;  // an Odometry's child_frame_id, from its first message

 private:
  std::string frame_;  // header.frame_id of the first message
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

// --stamp recorded: the reader orders messages by recording time. A recording clock that steps
// back (NTP, a resumed machine) gives the messages after the step earlier times, and ordering by
// them interleaves two stretches of the recording: wheel angles jump to and fro, a data set
// `fit` then refuses or, worse, fits. Refused naming the instant (the header stamps, the
// default, do not depend on the recorder's clock).
void RefuseRecordingClockStepBack(BagReader* bag, const BagStreams& out) {
  std::string file;
  const std::optional<ClockStepBack> step = bag->RecordingClockStepBack(&file);
  if (!step) return;
  ThrowBagError(InputErrorKind::kNonIncreasingTime, file,
                "the recording clock steps back by " + Seconds(step->before_ns - step->after_ns) +
                    " after " + Seconds(step->before_ns) + " (" +
                    Seconds(step->before_ns - out.start_time_ns) +
                    " into the bag): recording times do not order the messages; import with "
                    "--stamp header");
}

// Header stamps out of order in the reader's (recording-time) order. When the recording clock
// stepped back the recording times interleave two stretches of the recording, while the
// drivers' stamps still order every stream: the streams are put in header-stamp order, with a
// note saying so. Otherwise (a driver reusing stamps, merged recordings) nothing changes and the
// first stamp out of order is reported by the caller.
void OrderByHeaderStamps(BagReader* bag, const BagStreamRequest& request, BagStreams* out) {
  if (request.stamp != StampSource::kHeader) return;
  std::string file;
  const std::optional<ClockStepBack> step = bag->RecordingClockStepBack(&file);
  if (!step) return;
  SortByStamp(&out->joints, request.joints.size());
  SortByStamp(&out->poses);
  out->notes.push_back(file + ": the recording clock steps back by " +
                       Seconds(step->before_ns - step->after_ns) + " after " +
                       Seconds(step->before_ns - out->start_time_ns) +
                       " into the bag: the messages are put in the order of their header stamps");
}

// Header stamps on a clock other than the recorder's (simulated time from 0, a robot clock never
// synchronised) lie far from the recording times, and t = 0 at the recording's start put the
// data set's times at -1.7e9 s, where --runs cannot name them. Then t = 0 is the first stamp.
// A minute apart: a synchronised clock and a recorder's queue differ by far less.
void StartAtFirstStampOnAnotherClock(std::int64_t first_recorded_ns, BagStreams* out) {
  constexpr std::int64_t kAnotherClockNs = 60'000'000'000;
  const std::int64_t first_stamp_ns = out->joints.t_ns.front();
  if (std::abs(first_stamp_ns - first_recorded_ns) <= kAnotherClockNs) return;
  out->start_time_ns = std::min(first_stamp_ns, out->poses.t_ns.front());
  out->notes.push_back("the header stamps run on another clock than the recorder's (the first "
                       "encoder message stamped " + Seconds(first_stamp_ns - first_recorded_ns) +
                       " from its recording time): t = 0 at the first header stamp");
}

// A storage file opened alone that its directory's metadata.yaml lists among others: one part of
// a split bag, read as if it were the whole (the others' messages left out, unsaid before).
std::optional<std::string> PartOfSplitBagNote(const std::string& file) {
  const OwningBag bag = OwningBagOfFile(file);
  if (bag.files < 2) return std::nullopt;
  return file + ": one of the " + std::to_string(bag.files) + " files of the split bag " +
         bag.directory + " (its metadata.yaml), read alone: " +
         (bag.files == 2 ? std::string("the other is")
                         : "the other " + std::to_string(bag.files - 1) + " are") +
         " left out; give the directory to read the whole bag";
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
  if (bag.metadata() == nullptr) {
    if (std::optional<std::string> note = PartOfSplitBagNote(bag_path)) out.notes.push_back(*note);
  }
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
  const TopicInfo* tf_static = bag.FindTopic(kTfStaticTopic);
  if (tf_static != nullptr && tf_static->type != kTfType) tf_static = nullptr;
  out.has_tf_static = tf_static != nullptr;
  BagMessage m;
  std::optional<std::int64_t> first_recorded_ns;  // the first encoder message's recording time
  while (bag.ReadNext(&m)) {
    if (m.topic == joint_topic) {
      if (!first_recorded_ns) first_recorded_ns = m.time_ns;
      joints.Add(m);
    } else if (m.topic == pose_topic) {
      poses.Add(m);
    } else if (m.topic == tf_static) {
      for (TransformStamped& t : DecodeTfMessage(m.payload, Describe(m)).transforms) {
        out.static_transforms.push_back(std::move(t));
      }
    }
  }
  out.pose_frame = out.pose_type == kOdometryType ? poses.child_frame : request.child_frame;
  joints.Finish(bag_path);
  if (request.stamp == StampSource::kRecorded) RefuseRecordingClockStepBack(&bag, out);
  if (joints.order.violated() || poses.order.violated()) {
    OrderByHeaderStamps(&bag, request, &out);
    if (!StrictlyIncreasing(out.joints.t_ns)) joints.order.ThrowIfViolated();
    if (!StrictlyIncreasing(out.poses.t_ns)) poses.order.ThrowIfViolated();
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
  if (request.stamp == StampSource::kHeader) {
    StartAtFirstStampOnAnotherClock(*first_recorded_ns, &out);
  }
  return out;
}

}  // namespace fitcal::io::rosbag2
