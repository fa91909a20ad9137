#include "models/mounted_model.h"

#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"
#include "models/pose_errors.h"
#include "odometry/aligned_run.h"

namespace fitcal {

namespace {

constexpr const char* kFrameKey = "ground_truth_frame";
// Default search box around the nominal frame: a guess of where a sensor sits is rarely off by
// more than a robot's length or a quarter turn; the user widens it under `bounds:`.
constexpr double kDefaultHalfWidthM = 2.0;
constexpr double kDefaultHalfWidthDeg = 90.0;
// Sideways speed of the probe twist that tells a robot that can move sideways (m/s).
constexpr double kSidewaysProbeMS = 0.1;

const char* const kBoundsKeys[MountedModel::kNumMountParameters] = {
    "ground_truth_x_m", "ground_truth_y_m", "ground_truth_yaw_deg"};

// The model's pose over windows, then a map of (pose, mount) to the residual of each window.
// The inner cost is the model's SegmentCost with identity ground truth and unit weights, whose
// residual is the window's odometry motion P itself (3 values; fit/track_residual.h does the
// same); the map is differentiated with Jets in (P, X) and chained with dP/dp.
class MountedCost final : public ceres::CostFunction {
 public:
  using Jet = ceres::Jet<double, 6>;  // P (x, y, theta), then X (x, y, yaw)
  // residual of window w (3 values) from its sensor motion X^-1 P X.
  using Map = std::function<void(int w, const Pose2<Jet>& sensor_motion, Jet* residual)>;

  MountedCost(ceres::CostFunction* inner, int num_inner_parameters, Map map)
      : inner_(inner), n_(num_inner_parameters), map_(std::move(map)) {
    set_num_residuals(inner->num_residuals());
    mutable_parameter_block_sizes()->push_back(n_ + MountedModel::kNumMountParameters);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int m = num_residuals();
    const int q = n_ + MountedModel::kNumMountParameters;
    std::vector<double> pose(m), pose_jacobian;
    const bool want = jacobians != nullptr && jacobians[0] != nullptr;
    if (want) pose_jacobian.assign(static_cast<std::size_t>(m) * n_, 0.0);
    double* inner_jacobians[1] = {want ? pose_jacobian.data() : nullptr};
    if (!inner_->Evaluate(parameters, pose.data(), want ? inner_jacobians : nullptr)) return false;
    const double* mount = parameters[0] + n_;
    const Jet x[3] = {Jet(mount[0], 3), Jet(mount[1], 4), Jet(mount[2], 5)};
    for (int w = 0; w < m / 3; ++w) {
      const Pose2<Jet> d{Jet(pose[3 * w], 0), Jet(pose[3 * w + 1], 1), Jet(pose[3 * w + 2], 2)};
      Jet r[3];
      map_(w, ConjugateByMount(x, d), r);
      for (int i = 0; i < 3; ++i) {
        const int row = 3 * w + i;
        residuals[row] = r[i].a;
        if (!want) continue;
        double* out = jacobians[0] + static_cast<std::size_t>(row) * q;
        for (int j = 0; j < n_; ++j) {  // dr/dp = dr/dP dP/dp
          double sum = 0.0;
          for (int c = 0; c < 3; ++c) sum += r[i].v[c] * pose_jacobian[(3 * w + c) * n_ + j];
          out[j] = sum;
        }
        for (int j = 0; j < 3; ++j) out[n_ + j] = r[i].v[3 + j];
      }
    }
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  int n_;
  Map map_;
};

// The inner kinematics' step, conjugated by the mount p[n .. n + 3).
template <typename T>
class MountedPrepared final : public PreparedKinematics<T> {
 public:
  MountedPrepared(std::unique_ptr<const PreparedKinematics<T>> inner, const T* mount)
      : inner_(std::move(inner)), mount_{mount[0], mount[1], mount[2]} {}
  void Step(const T* values, double dt, T* dx, T* dy, T* dtheta) const override {
    Pose2<T> d;
    inner_->Step(values, dt, &d.x, &d.y, &d.theta);
    const Pose2<T> s = ConjugateByMount(mount_, d);
    *dx = s.x;
    *dy = s.y;
    *dtheta = s.theta;
  }

 private:
  std::unique_ptr<const PreparedKinematics<T>> inner_;
  T mount_[3];
};

// a b
Pose2d Compose(const Pose2d& a, const Pose2d& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.theta + b.theta};
}

Robot MountedRobot(const Robot& inner, const GroundTruthFrame& frame,
                   const std::vector<Interval>& bounds, bool moves_sideways) {
  Robot robot = inner;
  const int n = inner.NumParameters();
  robot.parameters.push_back({"ground_truth_x", kBoundsKeys[0], ParameterUnit::kLength});
  robot.parameters.push_back({"ground_truth_y", kBoundsKeys[1], ParameterUnit::kLength});
  robot.parameters.push_back({"ground_truth_yaw", kBoundsKeys[2], ParameterUnit::kAngle});
  robot.nominal.insert(robot.nominal.end(), {frame.x_m, frame.y_m, frame.yaw_rad});
  robot.bounds.insert(robot.bounds.end(), bounds.begin(), bounds.end());
  if (moves_sideways) {
    const std::string reason =
        "a robot that moves sideways has no point its wheels fix: a shift of the pose source "
        "is a change of the wheel distances (R_i' = R_i - x cos delta_i - y sin delta_i), so the "
        "runs cannot tell the two apart; held at the robot YAML's ground_truth_frame";
    robot.held.push_back({n, reason});
    robot.held.push_back({n + 1, reason});
  }
  return robot;
}

bool MovesSideways(const RobotModelInterface& model) {
  std::vector<double> values(model.robot().NumChannels());
  return model.ChannelsForTwist(model.robot().nominal.data(), Twist{0.0, kSidewaysProbeMS, 0.0},
                                values.data());
}

}  // namespace

MountedModel::MountedModel(RobotModelPtr inner, const GroundTruthFrame& frame,
                           const std::vector<Interval>& bounds, bool hold_sideways)
    : inner_(std::move(inner)),
      robot_(MountedRobot(inner_->robot(), frame, bounds,
                          hold_sideways && MovesSideways(*inner_))) {}

RobotModelPtr MountedModel::WithSidewaysMountFreed() const {
  const int n = MountIndex();
  if (!robot_.IsHeld(n)) return nullptr;
  const std::vector<double>& nominal = robot_.nominal;
  const GroundTruthFrame frame{nominal[n], nominal[n + 1], nominal[n + 2]};
  const std::vector<Interval> bounds(robot_.bounds.begin() + n, robot_.bounds.end());
  return std::make_shared<MountedModel>(inner_, frame, bounds, false);
}

Pose2d MountedModel::Replay(const double* p, const EncoderSamples& samples, std::size_t begin,
                            std::size_t end, const Pose2d& start, const PoseVisitor& visit) const {
  const double* mount = p + MountIndex();
  PoseVisitor inner_visit;
  if (visit) {
    inner_visit = [&](std::size_t k, const Pose2d& d) {
      visit(k, Compose(start, ConjugateByMount(mount, d)));
    };
  }
  const Pose2d d = inner_->Replay(p, samples, begin, end, Pose2d{}, inner_visit);
  return Compose(start, ConjugateByMount(mount, d));
}

// Palacin Eq. 14 on the sensor: S_0 X^-1 D X against the ground truth's final pose, S_0 the
// ground truth's start pose.
ceres::CostFunction* MountedModel::FinalPoseCost(const AlignedRun& run,
                                                 const ResidualWeights& weights) const {
  // `whole` must outlive the inner cost, which keeps a reference: the map owns it.
  auto whole = std::make_shared<std::vector<Segment>>(1);
  (*whole)[0].begin = 0;
  (*whole)[0].end = run.samples.size();
  ceres::CostFunction* inner = inner_->SegmentCost(run, *whole, ResidualWeights{});
  const Pose2d start = run.start;
  const Pose2d final_ground_truth = run.final_ground_truth;
  return new MountedCost(inner, MountIndex(),
                         [whole, start, final_ground_truth, weights](
                             int, const Pose2<MountedCost::Jet>& s, MountedCost::Jet* r) {
                           using std::cos;
                           using std::sin;
                           using Jet = MountedCost::Jet;
                           const double c = std::cos(start.theta), sn = std::sin(start.theta);
                           const Pose2<Jet> world{start.x + c * s.x - sn * s.y,
                                                  start.y + sn * s.x + c * s.y,
                                                  start.theta + s.theta};
                           FinalPoseError(world, final_ground_truth, weights, r);
                         });
}

// The segment error of models/pose_errors.h on the sensor's motion over each window.
ceres::CostFunction* MountedModel::SegmentCost(const AlignedRun& run,
                                               const std::vector<Segment>& segments,
                                               const ResidualWeights& weights) const {
  auto identity = std::make_shared<std::vector<Segment>>(segments);
  for (Segment& s : *identity) s.ground_truth_start_T_end = Pose2d{};
  ceres::CostFunction* inner = inner_->SegmentCost(run, *identity, ResidualWeights{});
  return new MountedCost(inner, MountIndex(),
                         [identity, &segments, weights](int w, const Pose2<MountedCost::Jet>& s,
                                                        MountedCost::Jet* r) {
                           const Pose2<MountedCost::Jet> origin{};
                           SegmentError(origin, s, segments[w].ground_truth_start_T_end, weights,
                                        r);
                         });
}

std::unique_ptr<const PreparedKinematics<double>> MountedModel::PrepareKinematics(
    const double* p) const {
  return std::make_unique<MountedPrepared<double>>(inner_->PrepareKinematics(p), p + MountIndex());
}

std::unique_ptr<const PreparedKinematics<EffectJet>> MountedModel::PrepareKinematics(
    const EffectJet* p) const {
  return std::make_unique<MountedPrepared<EffectJet>>(inner_->PrepareKinematics(p),
                                                      p + MountIndex());
}

std::string MountedModel::RobotYaml(const std::vector<double>& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    const std::string& calibration_block) const {
  const int n = MountIndex();
  std::string text =
      inner_->RobotYaml(std::vector<double>(p.begin(), p.begin() + n), effects, "");
  // The frame's bounds join the inner model's `bounds:` block (a top-level block map whose
  // entries are indented two spaces), or make one: ASOC writes its bounds only when its robot
  // YAML declared them.
  YAML::Emitter bounds;
  bounds.SetDoublePrecision(10);
  bounds << YAML::BeginMap;
  for (int i = 0; i < kNumMountParameters; ++i) {
    const ParameterInfo& info = robot_.parameters[n + i];
    io::EmitBoundsPair(bounds, kBoundsKeys[i], robot_.bounds[n + i], info.DisplayScale());
  }
  bounds << YAML::EndMap;
  std::string indented;
  std::istringstream lines(bounds.c_str());
  for (std::string line; std::getline(lines, line);) indented += "  " + line + "\n";
  const std::size_t block = text.find("\nbounds:\n");
  if (block == std::string::npos) {
    if (!text.empty() && text.back() != '\n') text += "\n";
    text += "bounds:\n" + indented;
  } else {
    std::size_t end = block + 9;
    while (end < text.size() && text.compare(end, 2, "  ") == 0) end = text.find('\n', end) + 1;
    text.insert(end, indented);
  }
  YAML::Emitter frame;
  frame.SetDoublePrecision(10);
  frame << YAML::BeginMap << YAML::Key << kFrameKey << YAML::Value << YAML::Flow << YAML::BeginMap
        << YAML::Key << "x_m" << YAML::Value << p[n] << YAML::Key << "y_m" << YAML::Value
        << p[n + 1] << YAML::Key << "yaw_deg" << YAML::Value << RadToDeg(p[n + 2]) << YAML::EndMap
        << YAML::EndMap;
  return text + frame.c_str() + "\n" + calibration_block;
}

std::vector<ClosedFormCalibration> MountedModel::ClosedForms(
    const std::vector<AlignedRun>& training) const {
  // A closed form knows the base only: it competes with the nominal frame.
  std::vector<ClosedFormCalibration> out = inner_->ClosedForms(training);
  for (ClosedFormCalibration& c : out) {
    c.parameters.insert(c.parameters.end(), robot_.nominal.begin() + MountIndex(),
                        robot_.nominal.end());
    // The frame is not measured by it: NaN leaves its sigma to the propagated uncertainty.
    if (!c.sigma.empty()) {
      c.sigma.resize(c.parameters.size(), std::numeric_limits<double>::quiet_NaN());
    }
  }
  return out;
}

const RobotModelInterface& BaseModel(const RobotModelInterface& model) {
  const auto* mounted = dynamic_cast<const MountedModel*>(&model);
  return mounted == nullptr ? model : mounted->inner();
}

namespace {

// "x", "x and y", "x, y and yaw".
std::string Enumerate(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  }
  return out;
}

}  // namespace

std::vector<int> MountParameterIndices(const Robot& robot) {
  const std::optional<int> first = ParameterIndex(robot, "ground_truth_x");
  if (!first) return {};
  return {*first, *first + 1, *first + 2};
}

bool IsMountPosition(const Robot& robot, int k) {
  const std::vector<int> mount = MountParameterIndices(robot);
  return !mount.empty() && (k == mount[0] || k == mount[1]);
}

std::string HeldMountNote(const Robot& robot, const std::vector<double>& parameters,
                          const std::vector<bool>& held) {
  std::ostringstream names;
  for (int k : MountParameterIndices(robot)) {
    if (k >= static_cast<int>(held.size()) || !held[k]) continue;
    const ParameterInfo& info = robot.parameters[k];
    names << (names.tellp() > 0 ? ", " : "") << info.name << " "
          << info.DisplayScale() * parameters[k] << " " << info.DisplayUnit();
  }
  if (names.tellp() == 0) return "";
  return "; the ground truth's mount is held at its guess (" + names.str() +
         "), which these runs cannot tell from the wheels' geometry: an error in the guess moves "
         "into the wheels' parameters - measure the mount and set ground_truth_frame";
}

std::string GroundTruthFrameLine(const Robot& robot, const std::vector<bool>& held,
                                 const std::string& held_reason,
                                 const std::vector<bool>& not_determined) {
  const std::vector<int> mount = MountParameterIndices(robot);
  if (mount.empty()) return "";
  const char* const names[] = {"x", "y", "yaw"};
  std::vector<std::string> determined, open, fixed;
  std::string reason = "--hold, or a direction the runs do not determine";
  for (int i = 0; i < MountedModel::kNumMountParameters; ++i) {
    const int k = mount[i];
    // A fitted number on a direction the runs leave open (an omni robot's yaw turning with a
    // common offset of its wheel angles) moves with the nominal there: not "determined".
    const bool on_open_direction =
        k < static_cast<int>(not_determined.size()) && not_determined[k];
    (held[k] ? fixed : on_open_direction ? open : determined).push_back(names[i]);
    for (const HeldParameter& h : robot.held) {
      if (h.index == k) reason = h.reason;
    }
  }
  if (!held_reason.empty()) reason = held_reason;
  std::string line = "ground_truth_frame: ";
  std::vector<std::string> parts;
  if (!determined.empty()) parts.push_back(Enumerate(determined) + " determined by the runs");
  if (!open.empty()) {
    parts.push_back(Enumerate(open) + " not determined (on a direction the runs leave open, " +
                    "with the parameters marked NOT DETERMINED)");
  }
  if (!fixed.empty()) parts.push_back(Enumerate(fixed) + " held (" + reason + ")");
  for (std::size_t i = 0; i < parts.size(); ++i) line += (i == 0 ? "" : "; ") + parts[i];
  return line;
}

RobotModelPtr ApplyGroundTruthFrame(YAML::Node root, const std::string& path,
                                    const std::function<RobotModelPtr(const YAML::Node&)>& read) {
  // Looked up through a const node: a non-const lookup of an absent key would add it.
  const YAML::Node& lookup = root;
  const YAML::Node node = lookup[kFrameKey];
  if (!node) return read(root);
  io::YamlMap map(node, path, kFrameKey);
  GroundTruthFrame frame;
  frame.x_m = map.Double("x_m");
  frame.y_m = map.Double("y_m");
  frame.yaw_rad = DegToRad(map.Double("yaw_deg"));
  map.RejectUnread();
  const double nominal[3] = {frame.x_m, frame.y_m, frame.yaw_rad};
  const double half[3] = {kDefaultHalfWidthM, kDefaultHalfWidthM, DegToRad(kDefaultHalfWidthDeg)};
  const double scale[3] = {1.0, 1.0, M_PI / 180.0};
  std::vector<Interval> bounds(3);
  YAML::Node bounds_node = lookup["bounds"];
  const YAML::Node& bounds_lookup = bounds_node;
  for (int i = 0; i < 3; ++i) {
    bounds[i] = {nominal[i] - half[i], nominal[i] + half[i]};
    if (!bounds_node || !bounds_node.IsMap() || !bounds_lookup[kBoundsKeys[i]]) continue;
    io::YamlMap box(bounds_node, path, "bounds");
    bounds[i] = io::ReadBoundsPair(box, kBoundsKeys[i], scale[i]);
    if (!bounds[i].Contains(nominal[i])) {
      throw io::InputError(io::InputErrorKind::kBadValue, path,
                           box.line(bounds_lookup[kBoundsKeys[i]]),
                           std::string("ground_truth_frame lies outside bounds.") + kBoundsKeys[i]);
    }
  }
  // The model's reader knows its own schema only (it rejects keys it did not read); a block that
  // held only the frame's bounds goes with them (ASOC reads a `bounds:` as all of its own).
  for (const char* key : kBoundsKeys) {
    if (bounds_node && bounds_node.IsMap()) bounds_node.remove(key);
  }
  if (bounds_node && bounds_node.IsMap() && bounds_node.size() == 0) root.remove("bounds");
  root.remove(kFrameKey);
  RobotModelPtr inner = read(root);
  for (const effects::EffectValue& e : inner->robot().effects) {
    if (e.id != effects::EffectId::kGroundTruthOffset) continue;
    // Both would move the tracked point: the fitted frame (with its yaw) replaces the effect.
    throw io::InputError(io::InputErrorKind::kBadValue, path, map.line(node),
                         "ground_truth_frame and the effect ground_truth_offset both place the "
                         "tracked point; keep ground_truth_frame and drop the effect");
  }
  return std::make_shared<MountedModel>(std::move(inner), frame, bounds);
}

}  // namespace fitcal
