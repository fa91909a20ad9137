#pragma once
// The robots of the OptiOdom study (Sousa et al., "OptiOdom: a Generic Approach for Odometry
// Calibration of Wheeled Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT licence;
// ../shared/data/optiodom/README.md) by their metadata `type`: what differs between them, as
// data and two hooks (the nominal model, the check of an angle column). Everything else is the
// one import sequence (cli/import_optiodom.h) over the one reader and writer of the format
// (optiodom_format.h), so that the sequence names no model.

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "interchange/optiodom/optiodom_format.h"

namespace fitcal::optiodom {

// A metadata row that describes the robot (read after ngear and encRes, in this order). Sessions
// whose rows differ declare perturbed starting values (the README): the majority's make the robot.
struct GeometryRow {
  const char* key;    // Li, Di, Thi
  int count;          // values the row holds
  bool positive;      // each must be > 0
  const char* label;  // its name in the notes ("b" for the diff drive's wheel separation)
  const char* unit;   // printed after its values
};

struct RobotKind {
  const char* type;                   // metadata `type`
  std::vector<GeometryRow> geometry;  // makes the nominal robot; compared between sessions
  const char* file_columns;           // the run files' encoder columns as the authors name them
  double tick_sign;                   // our channel = tick_sign * the file's ticks
  int time_decimals;                  // of t in the ticks CSV (as earlier imports wrote it)
  char id_separator;                  // run id <path><sep><session><sep>runNN
  char trajectory_separator;          // trajectory <path><sep><session>, repetition NN ...
  bool label_by_direction;            // ... or <path>_cw / _ccw, repetition = the session's place
  const char* file_comment;           // when set, heads robot.yaml and dataset.yaml, then the notes
  // The nominal robot of the majority's metadata, with the box the fit may search; a robot with
  // `encoder` set is written as ticks, one without as wheel rates.
  RobotModelPtr (*nominal_model)(const Metadata& metadata);
  // The model's check of the angle column's readings (radians as the file holds them, row k on
  // line first_line + k of `path`): io::InputError on a bad one; nullptr without an angle column.
  void (*check_readings)(const std::vector<double>& readings_rad, const std::string& path,
                         int first_line);
};

// The robot of sessions of this `type`; io::InputError naming `session` for any other.
const RobotKind& RobotKindOf(const std::string& type, const std::string& session);

// A run the authors flagged as bad, or nullptr.
const char* FlaggedRunReason(const std::string& path_type, const std::string& session, int run);

}  // namespace fitcal::optiodom
