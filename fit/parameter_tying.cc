#include "fit/parameter_tying.h"

#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <algorithm>
#include <map>
#include <stdexcept>

#include "io/text_file.h"
#include "models/mounted_model.h"

namespace fitcal {

namespace {

constexpr const char* kHeldReason = "held at its nominal value by the parameter tying";

std::string NamesOf(const Robot& robot) {
  return io::Joined(robot.parameters, ", ", [](const ParameterInfo& info) { return info.name; });
}

// The chain rule through p = A q: J_q = J_p A, i.e. column j of J_q sums the columns of J_p of
// the parameters tied to q_j.
class TiedCost final : public ceres::CostFunction {
 public:
  TiedCost(ceres::CostFunction* inner, std::vector<int> group_of, int num_q)
      : inner_(inner), group_of_(std::move(group_of)), num_q_(num_q) {
    set_num_residuals(inner->num_residuals());
    mutable_parameter_block_sizes()->push_back(num_q);
  }

  bool Evaluate(double const* const* q, double* residuals, double** jacobians) const override {
    const int n = static_cast<int>(group_of_.size());
    std::vector<double> p(n);
    for (int k = 0; k < n; ++k) p[k] = q[0][group_of_[k]];
    const double* p_blocks[] = {p.data()};
    if (jacobians == nullptr || jacobians[0] == nullptr) {
      return inner_->Evaluate(p_blocks, residuals, nullptr);
    }
    const int r = num_residuals();
    std::vector<double> j_p(static_cast<std::size_t>(r) * n);
    double* j_blocks[] = {j_p.data()};
    if (!inner_->Evaluate(p_blocks, residuals, j_blocks)) return false;
    std::fill(jacobians[0], jacobians[0] + static_cast<std::size_t>(r) * num_q_, 0.0);
    for (int i = 0; i < r; ++i) {
      for (int k = 0; k < n; ++k) jacobians[0][i * num_q_ + group_of_[k]] += j_p[i * n + k];
    }
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  std::vector<int> group_of_;
  int num_q_;
};

// The inner model's kinematics at p = A q; owns p, which the inner prepared kinematics may read.
template <typename T>
class TiedPrepared final : public PreparedKinematics<T> {
 public:
  TiedPrepared(const RobotModelInterface& inner, std::vector<T> p)
      : p_(std::move(p)), inner_(inner.PrepareKinematics(p_.data())) {}
  void Step(const T* values, double dt, T* dx, T* dy, T* dtheta) const override {
    inner_->Step(values, dt, dx, dy, dtheta);
  }

 private:
  std::vector<T> p_;
  std::unique_ptr<const PreparedKinematics<T>> inner_;
};

// ground_truth_x, _y, _yaw (models/mounted_model.h): the pose of the frame the ground truth
// tracks, which no wheel's size or place can share a value with.
bool IsMount(const Robot& robot, int k) {
  const std::vector<int> mount = MountParameterIndices(robot);
  return std::find(mount.begin(), mount.end(), k) != mount.end();
}

// Every name in `tying` resolved to its index; "" or the first problem.
std::string ResolveNames(const Robot& robot, const ParameterTying& tying,
                         std::vector<std::vector<int>>* groups, std::vector<int>* held) {
  std::map<std::string, int> seen;
  const auto resolve = [&](const std::string& name, int* k) -> std::string {
    const std::optional<int> index = ParameterIndex(robot, name);
    if (!index) {
      return "parameter tying: robot '" + robot.name + "' (model " + robot.model +
             ") has no parameter '" + name + "' (its parameters: " + NamesOf(robot) + ")";
    }
    if (seen[name]++ > 0) return "parameter tying: '" + name + "' is named twice";
    *k = *index;
    return "";
  };
  for (const std::vector<std::string>& names : tying.groups) {
    if (names.size() < 2) {
      return "parameter tying: a group needs two or more parameters ('" +
             (names.empty() ? std::string() : names[0]) + "')";
    }
    groups->emplace_back();
    for (const std::string& name : names) {
      int k = 0;
      if (const std::string e = resolve(name, &k); !e.empty()) return e;
      if (robot.IsHeld(k)) {
        return "parameter tying: '" + name + "' is held by the model and cannot be tied";
      }
      if (!groups->back().empty() &&
          robot.parameters[k].unit != robot.parameters[groups->back()[0]].unit) {
        return "parameter tying: a group mixes lengths and angles ('" + name + "')";
      }
      if (!groups->back().empty() && IsMount(robot, k) != IsMount(robot, groups->back()[0])) {
        return "parameter tying: a group mixes the ground truth's mount with the robot's "
               "geometry ('" + robot.parameters[groups->back()[0]].name + "', '" + name +
               "'): the mount is where the sensor sits, not a wheel's size or place";
      }
      groups->back().push_back(k);
    }
  }
  for (const std::string& name : tying.held) {
    int k = 0;
    if (const std::string e = resolve(name, &k); !e.empty()) return e;
    held->push_back(k);
  }
  return "";
}

Interval Intersection(const Robot& robot, const std::vector<int>& members) {
  Interval box{-HUGE_VAL, HUGE_VAL};
  for (int k : members) {
    box.lo = std::max(box.lo, robot.bounds[k].lo);
    box.hi = std::min(box.hi, robot.bounds[k].hi);
  }
  return box;
}

}  // namespace

std::string CheckTying(const Robot& robot, const ParameterTying& tying) {
  std::vector<std::vector<int>> groups;
  std::vector<int> held;
  if (std::string e = ResolveNames(robot, tying, &groups, &held); !e.empty()) return e;
  // Holding every free parameter leaves an empty fit (no solver variable, no covariance to take
  // the determined directions from): said here, where the names are known, not met as a crash.
  int free = 0;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    free += !robot.IsHeld(k) && std::find(held.begin(), held.end(), k) == held.end();
  }
  if (free == 0) {
    return "parameter tying: --hold leaves nothing to fit (every parameter of robot '" +
           robot.name + "' is held: " + NamesOf(robot) + ")";
  }
  for (const std::vector<int>& members : groups) {
    const Interval box = Intersection(robot, members);
    if (!(box.lo <= box.hi)) {
      return "parameter tying: the bounds of " + robot.parameters[members[0]].name +
             " and the parameters tied to it do not overlap";
    }
  }
  return "";
}

TiedModel::TiedModel(const RobotModelInterface& inner, const ParameterTying& tying)
    : inner_(inner) {
  const Robot& p_robot = inner.robot();
  if (const std::string e = CheckTying(p_robot, tying); !e.empty()) throw std::invalid_argument(e);
  std::vector<std::vector<int>> groups;
  std::vector<int> held;
  ResolveNames(p_robot, tying, &groups, &held);
  const int n = p_robot.NumParameters();
  std::vector<int> group_index(n, -1);  // which of `groups` parameter k is in
  for (std::size_t g = 0; g < groups.size(); ++g) {
    for (int k : groups[g]) group_index[k] = static_cast<int>(g);
  }
  // q in the order of each group's first member; the robot of q names a group "R_a=R_b=R_c".
  robot_ = p_robot;
  robot_.parameters.clear();
  robot_.nominal.clear();
  robot_.bounds.clear();
  robot_.held.clear();
  group_of_.assign(n, -1);
  for (int k = 0; k < n; ++k) {
    if (group_of_[k] >= 0) continue;
    const int j = robot_.NumParameters();
    const std::vector<int> members =
        group_index[k] >= 0 ? groups[group_index[k]] : std::vector<int>{k};
    ParameterInfo info = p_robot.parameters[k];
    double nominal = 0.0;
    for (std::size_t i = 0; i < members.size(); ++i) {
      group_of_[members[i]] = j;
      nominal += p_robot.nominal[members[i]] / static_cast<double>(members.size());
      if (i > 0) info.name += "=" + p_robot.parameters[members[i]].name;
    }
    const Interval box = Intersection(p_robot, members);
    robot_.parameters.push_back(info);
    robot_.bounds.push_back(box);
    robot_.nominal.push_back(std::clamp(nominal, box.lo, box.hi));
  }
  for (const HeldParameter& h : p_robot.held) robot_.held.push_back({group_of_[h.index], h.reason});
  for (int k : held) {
    if (!robot_.IsHeld(group_of_[k])) robot_.held.push_back({group_of_[k], kHeldReason});
  }
}

Eigen::MatrixXd TiedModel::Basis() const {
  Eigen::MatrixXd a =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(group_of_.size()), robot_.NumParameters());
  for (std::size_t k = 0; k < group_of_.size(); ++k)
    a(static_cast<Eigen::Index>(k), group_of_[k]) = 1.0;
  return a;
}

template <typename T>
std::vector<T> TiedModel::ExpandAs(const T* q) const {
  std::vector<T> p(group_of_.size());
  for (std::size_t k = 0; k < p.size(); ++k) p[k] = q[group_of_[k]];
  return p;
}

std::vector<double> TiedModel::Expand(const double* q) const { return ExpandAs(q); }

std::vector<double> TiedModel::Reduce(const std::vector<double>& p) const {
  std::vector<double> q(robot_.NumParameters(), 0.0);
  std::vector<int> count(q.size(), 0);
  for (std::size_t k = 0; k < group_of_.size(); ++k) {
    q[group_of_[k]] += p[k];
    ++count[group_of_[k]];
  }
  for (std::size_t j = 0; j < q.size(); ++j) q[j] /= count[j];
  return q;
}

Pose2d TiedModel::Replay(const double* q, const EncoderSamples& samples, std::size_t begin,
                         std::size_t end, const Pose2d& start, const PoseVisitor& visit) const {
  return inner_.Replay(Expand(q).data(), samples, begin, end, start, visit);
}

ceres::CostFunction* TiedModel::Wrap(ceres::CostFunction* inner_cost) const {
  return new TiedCost(inner_cost, group_of_, robot_.NumParameters());
}

ceres::CostFunction* TiedModel::FinalPoseCost(const AlignedRun& run,
                                              const ResidualWeights& weights) const {
  return Wrap(inner_.FinalPoseCost(run, weights));
}

ceres::CostFunction* TiedModel::SegmentCost(const AlignedRun& run,
                                            const std::vector<Segment>& segments,
                                            const ResidualWeights& weights) const {
  return Wrap(inner_.SegmentCost(run, segments, weights));
}

std::unique_ptr<const PreparedKinematics<double>> TiedModel::PrepareKinematics(
    const double* q) const {
  return std::make_unique<TiedPrepared<double>>(inner_, ExpandAs(q));
}

std::unique_ptr<const PreparedKinematics<EffectJet>> TiedModel::PrepareKinematics(
    const EffectJet* q) const {
  return std::make_unique<TiedPrepared<EffectJet>>(inner_, ExpandAs(q));
}

bool TiedModel::StepMatrix(const double* q, double* m) const {
  return inner_.StepMatrix(Expand(q).data(), m);
}

bool TiedModel::ChannelsForTwist(const double* q, const Twist& twist, double* values) const {
  return inner_.ChannelsForTwist(Expand(q).data(), twist, values);
}

std::string TiedModel::RobotYaml(const std::vector<double>& q,
                                 const std::vector<effects::EffectValue>& effects,
                                 const std::string& calibration_block) const {
  return inner_.RobotYaml(Expand(q.data()), effects, calibration_block);
}

}  // namespace fitcal
