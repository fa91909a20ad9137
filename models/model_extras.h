#pragma once
// What a model offers beyond the seam, registered with it (model_registry.h,
// ModelRegistration::extras) from its own folder: the ROS 2 controllers it can be exported to,
// the trajectories the simulator calibrates it on, how `compare` shows its parameters. Every field
// is optional. The commands ask the
// registry for these and never compare a model's name (STYLE.md habit 14).

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "models/trajectory_spec.h"

namespace fitcal {

// What a controller's parameters are, and what the controller computes from them as written
// (12 significant digits), for the export's replay: the calibrated model at the representable
// values, or a model of the controller's own geometry (cli/export_ros2_control.h).
struct ControllerExport {
  std::string parameters_yaml;     // `<node>:\n  ros__parameters:\n    ...` without the comments
  std::vector<std::string> notes;  // one line per parameter the controller cannot represent
  RobotModelPtr model;
  std::vector<double> parameters;  // model->robot().parameters order
};

// The calibrated robot a writer reads, and the joint of each channel.
struct CalibratedRobot {
  RobotModelPtr model;
  std::vector<std::string> joints;  // robot channel order
  const Robot& robot() const { return model->robot(); }
  // The calibrated value of a parameter, found by name in the model's parameter table.
  int Index(const std::string& name) const { return RequireParameterIndex(robot(), name); }
  const std::string& ChannelName(int i) const { return robot().channels[i].name; }
};

// A geometry the controller cannot describe at all (mecanum rollers the wrong way): the command
// refuses it as a usage error (exit 2).
class ControllerCannotDescribe : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Appends the parameter lines and notes to `out` and sets the controller's kinematics; throws
// ControllerCannotDescribe.
using ControllerWriteFn =
    std::function<void(const CalibratedRobot&, const std::string& distro, ControllerExport* out)>;

struct ControllerWriter {
  std::string controller;  // ros2_controllers' name, e.g. "diff_drive_controller"
  std::string distros;     // the ROS 2 distributions that ship it, space-separated
  ControllerWriteFn write;
};

// The trajectories `simulate --model` drives the model on (sim/model_scenarios.h), and
// how far its default true robot is from the nominal one (a fraction of the way to the bounds).
// The commands are the nominal robot's; the true parameters may only limit what the machine can
// drive (a tricycle's readable steering range).
// A channel that is a state of the machine, not a function of the body twist (an ASOC castor's
// angle follows its pivot's motion: asoc_extras.h). The simulator's perfect tracking asks the
// model's dynamics for every fine step in place of ChannelsForTwist.
class ChannelDynamics {
 public:
  virtual ~ChannelDynamics() = default;
  // Advances the state by dt_s under the body twist v (held over the step) and writes the step's
  // channel values as the seam's replay reads them: wheel rates as the step's mean, angles at its
  // middle.
  virtual void Step(const Twist& v, double dt_s, double* values) = 0;
  // The angle channels' encoder readings now (wheel channels are left as they are).
  virtual void Read(double* values) const = 0;
};
using ChannelDynamicsFactory = std::function<std::unique_ptr<ChannelDynamics>(
    const RobotModelInterface& model, const std::vector<double>& truth,
    const sim::TrajectorySpec& spec)>;

struct SimulationScenario {
  std::function<std::vector<sim::TrajectorySpec>(
      const RobotModelInterface& nominal, const std::vector<double>& truth, int repetitions)>
      trajectories;  // empty: the model has no scenario
  double truth_fraction = 0.25;
  // The default true robot when the model has its own (omni3: Palacin Table 5, any seed; asoc:
  // drawn from `seed` as Doebbler Table I); empty: the nominal moved truth_fraction of the way to
  // its bounds.
  std::function<std::vector<double>(const Robot& nominal, std::uint64_t seed)> default_truth;
  // Empty: every channel follows the twist (ChannelsForTwist).
  ChannelDynamicsFactory dynamics;
  // Driven through the time-stepped physics of a wheel controller (sim/stepped_run.h: lag, slip,
  // jittered encoders, irregular ground truth; `--slip-sigma` and `--inject` act there) and the
  // encoders written as a recorder writes them, instead of perfect tracking: how data/flower was
  // made, and its bytes are reproduced so.
  bool stepped_physics = false;
};

// How `compare` shows a row's parameters (its Markdown column and CSV columns).
struct ParameterDisplay {
  std::string markdown_header;
  std::vector<std::string> csv_names;
  std::function<std::vector<double>(const std::vector<double>&)> csv_values;
  std::function<std::string(const std::vector<double>&)> markdown;
};

struct ModelExtras {
  std::vector<ControllerWriter> controllers;
  SimulationScenario scenario;
  // Empty: the parameters in display units (m, deg).
  std::function<ParameterDisplay(const Robot&)> display;
};

// A controller writer's notes, shared by the writers of every model.
double MeanValue(const std::vector<double>& v);
// "<key> takes one <what>: the calibrated lo..hi <unit> are written as their mean" when the
// values differ.
void NoteSpread(const std::vector<double>& v, const std::string& what, const std::string& key,
                double scale, const char* unit, std::vector<std::string>* notes);

}  // namespace fitcal
