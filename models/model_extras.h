#pragma once
// What a model offers beyond the seam, registered with it (model_registry.h,
// ModelRegistration::extras) from its own folder: the ROS 2 controllers it can be exported to,
// the trajectories the simulator calibrates it on and how they are recorded, the closed forms it
// computes, a published table it reproduces, how `compare` shows its parameters. Every field is
// optional. The commands ask the registry for these and never compare a model's name (STYLE.md
// habit 14).

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "models/trajectory_spec.h"
#include "odometry/run_log.h"

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

// How a simulated data set is recorded (sim/model_scenarios.h turns it into the simulator's
// options; `simulate`'s noise flags replace single values). The defaults are a generic robot's
// (docs/simulate.md: 100 Hz encoders of 4096 counts with rate noise, 5 Hz ground truth with 2 mm
// and 0.2 deg of noise, runs started anywhere within +-2 m); a model whose paper recorded
// otherwise registers its own (asoc: Doebbler's 20 Hz prototype, asoc_extras.h).
struct ScenarioRecorder {
  double encoder_period_s = 0.010;
  double ticks_per_rev = 4096.0;         // wheel channels; 0 = no quantisation
  double wheel_rate_sigma_rad_s = 0.02;  // white noise on each interval's mean wheel rate
  // Each wheel's counted advance over an interval scaled by (1 + N(0, sigma)): a slip per sample.
  double wheel_relative_sigma = 0.0;
  double angle_sigma_rad = 0.1 * M_PI / 180.0;  // white noise on an angle channel's readings
  double ground_truth_period_s = 0.2;
  double gt_position_sigma_m = 0.002;
  double gt_heading_sigma_rad = 0.2 * M_PI / 180.0;
  double start_position_range_m = 2.0;  // each axis uniform in +-range about the origin
  bool random_start_heading = true;
  double substep_s = 0.0;  // the true motion's longest step; 0: the simulator's default
};

// The trajectories `simulate --model` drives the model on (sim/model_scenarios.h), how they are
// recorded, and how far its default true robot is from the nominal one (a fraction of the way to
// the bounds). The commands are the nominal robot's; the true parameters may only limit what the
// machine can drive (a tricycle's readable steering range).
struct SimulationScenario {
  std::function<std::vector<sim::TrajectorySpec>(
      const RobotModelInterface& nominal, const std::vector<double>& truth, int repetitions)>
      trajectories;  // empty: the model has no scenario
  int default_repetitions = 10;  // `simulate` without --repetitions
  // What a repetition is, as `simulate` counts them ("5 repetitions, seed 1"; asoc: excursions).
  std::string repetition_unit = "repetitions";
  ScenarioRecorder recorder;
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

// Runs of the true parameters `truth` (robot().parameters order) along the trajectories, as the
// model's recorder records them; `seed` the noise's (sim/model_scenarios.h ScenarioSimulator).
using SimulateFn = std::function<std::vector<RunLog>(const std::vector<double>& truth,
                                                     const std::vector<sim::TrajectorySpec>& specs,
                                                     std::uint64_t seed)>;

// What `fitcal paper-tables --model <name>` asks of a model that reproduces a paper's tables by
// Monte Carlo: `sets` random vehicles, drawn from `seed`, with the relative wheel noise of the
// recorder set to wheel_slip_sigma.
struct PaperTablesRequest {
  int sets = 1000;
  std::uint64_t seed = 1;
  double wheel_slip_sigma = 0.0;
  int threads = 0;  // 0 = all cores
};

// A paper's tables reproduced in simulation (asoc: Doebbler et al. Tables I and II,
// asoc_tables.h): the runs recorded as `recorder` says, the tables as printed, paper values beside.
struct PaperTables {
  ScenarioRecorder recorder;
  std::function<std::string(const RobotModelInterface& nominal, const PaperTablesRequest& request,
                            const SimulateFn& simulate)>
      reproduce;  // empty: the model reproduces no table
};

// A classical calibration computed from the training runs: its method's name (written as
// ClosedFormCalibration::method, so the name is given once) and the computation, nullopt when the
// runs hold nothing it can use.
struct ClosedForm {
  std::string method;  // "umbmark"
  std::function<std::optional<ClosedFormCalibration>(const RobotModelInterface& model,
                                                     const std::vector<AlignedRun>& training)>
      compute;
};

struct ModelExtras {
  std::vector<ControllerWriter> controllers;
  SimulationScenario scenario;
  // What RobotModelInterface::ClosedForms computes; empty: none, and `fit --closed-form-only` is
  // refused before any run is read.
  std::vector<ClosedForm> closed_forms;
  PaperTables paper_tables;
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
