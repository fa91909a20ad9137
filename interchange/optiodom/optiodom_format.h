#pragma once
// The published OptiOdom file format (Sousa et al., "OptiOdom: a Generic Approach for Odometry
// Calibration of Wheeled Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT licence;
// ../shared/data/optiodom/README.md), read once for every robot of the study:
//   <s>/<s>_metadata.csv  rows `key,v1,v2,...` (type, ngear, encRes, Li, Di, Thi, N, L, imarkers,
//                         gt_ti, gt_tf, odo_ti, odo_tf), padded with empty fields to the widest
//   <s>/<s>_run-NN.csv    no header, `t_s, x_gt_m, y_gt_m, theta_gt_rad, enc_1, ..., enc_m`
// Only the meaning of the encoder columns and of Li / Di differs between robots; that lives in the
// table of robots (interchange/optiodom/optiodom_robots.h). Every function throws io::InputError
// (file, line, cause) on bad input.

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "io/dataset.h"
#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal::optiodom {

// <s>_metadata.csv: the `type` row and every numeric row, key -> (line, values).
struct Metadata {
  std::string path;
  std::string type;
  std::map<std::string, std::pair<int, std::vector<double>>> rows;

  // Exactly `count` values of row `key`, each > 0 when `positive`.
  std::vector<double> Values(const std::string& key, std::size_t count, bool positive) const;
  double Value(const std::string& key, bool positive) const { return Values(key, 1, positive)[0]; }
  // N, a whole number of runs.
  int NumRuns() const;
  // ngear * encRes: encoder ticks per wheel revolution.
  double TicksPerWheelRev() const { return Value("ngear", true) * Value("encRes", true); }
};

// Reads the metadata and checks its type is `expected_type`; an unknown key is an error.
Metadata ReadMetadata(const std::string& path, const std::string& expected_type);

// The files of one session directory <path type>/<session>/.
struct SessionFiles {
  std::string name;       // directory name, e.g. 221220201643
  std::string path_type;  // parent directory name, e.g. circular, square ("path" if none)
  std::string metadata_path;
  std::vector<std::pair<int, std::string>> runs;  // (NN, path), sorted by NN
};

// Lists a session directory's run files; CheckRunCount holds them against the metadata's N.
SessionFiles ListSession(const std::string& directory);
void CheckRunCount(const SessionFiles& files, int num_runs);

// The `type` row of a session's metadata (diff, tricyc, omni3, omni4).
std::string SessionType(const std::string& directory);

// One run file: time, ground truth (start frame) and the encoder columns as written ("-0" -> 0).
struct RunRows {
  int number = 0;
  int first_line = 0;  // line of the first row
  std::vector<double> t_s;
  std::vector<std::vector<double>> encoder;  // encoder[k][j]: column j of row k
  GroundTruthTrack ground_truth;
};

// Reads a run file whose encoder columns are `column_names` ("ticks_right, ticks_left": their
// number, and their names in messages; a row one field short lacks the last of them).
RunRows ReadRun(const std::string& path, int number, const std::string& column_names);

// A run as fitcal replays it (the robot labels it: id, trajectory, repetition): wheel rates
// 2 pi / ticks_per_rev * increment(k) / dt over (t(k-1), t(k)] for every column but
// `reading_column` (an angle read at t(k): tricycle steering), which gets the mean of its readings
// at both ends of the interval; the ground truth, and the start pose: the robot is at rest at the
// start, the ground truth in its start frame.
RunLog RunLogOf(const RunRows& run, double ticks_per_rev, int reading_column);

// The encoder CSV of ticks as the robot logged them: header `t,<ticks column of each channel, or
// its rate column for an angle>`, then per row t (`time_decimals` fixed) and every column as
// %.10g; increments are 0 at row 0 (counted before the run), readings as read.
std::string TicksCsv(const Robot& robot, const RunRows& run, int time_decimals, int reading_column);

// The encoder CSV of wheel rates (header `t,<rate column of each channel>`, row 0 zero) and the
// ground-truth CSV (`t,x,y,theta`), every number in its shortest exact form (std::to_chars): for
// logs that are not ticks, nothing was rounded to a resolution on the way in.
std::string ExactRatesCsv(const Robot& robot, const RunLog& log);
std::string ExactGroundTruthCsv(const GroundTruthTrack& track);

// ---- Writing the fitcal data set (README.md "Data set format").

// Refuses a run id that two runs share (the same session given twice); `out` names the data set.
void CheckUniqueRunIds(const std::vector<RunLog>& runs, const std::string& out);

// How the data set's files read: each run's encoder CSV (ticks as logged, or rates), the
// ground-truth CSV, and comment lines put at the top of robot.yaml and dataset.yaml.
struct DatasetText {
  std::function<std::string(std::size_t run)> encoder_csv;
  std::function<std::string(const GroundTruthTrack&)> ground_truth_csv = io::GroundTruthCsv;
  std::string header;
};

// Writes runs/<id>_encoders.csv, runs/<id>_ground_truth.csv, robot.yaml (the model's nominal)
// and dataset.yaml (trajectory, repetition from each run) to `out`: staged beside it and renamed
// over it once complete, so a failure leaves nothing (io/staged_directory.h).
void WriteDataset(const std::vector<RunLog>& runs, const RobotModelInterface& model,
                  const DatasetText& text, const std::string& out, bool force,
                  const std::vector<std::string>& session_dirs);

}  // namespace fitcal::optiodom
