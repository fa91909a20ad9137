#pragma once
// The published OptiOdom file format (Sousa et al., "OptiOdom: a Generic Approach for Odometry
// Calibration of Wheeled Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT licence;
// ../shared/data/optiodom/README.md), read once for every robot of the study:
//   <s>/<s>_metadata.csv  rows `key,v1,v2,...` (type, ngear, encRes, Li, Di, Thi, N, L, imarkers,
//                         gt_ti, gt_tf, odo_ti, odo_tf), padded with empty fields to the widest
//   <s>/<s>_run-NN.csv    no header, `t_s, x_gt_m, y_gt_m, theta_gt_rad, enc_1, ..., enc_m`
// Only the meaning of the encoder columns and of Li / Di differs between robots; that lives in the
// per-robot importers. Every function throws io::InputError (file, line, cause) on bad input.

#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/dataset.h"
#include "models/model_interface.h"
#include "odometry/parallel_for.h"
#include "odometry/run_log.h"

namespace fitcal::tools::optiodom {

// The comma-separated fields of one line, each trimmed.
std::vector<std::string> SplitCsv(std::string_view line);

// A finite number, or InputError(path:line: `what` is not a finite number: '<field>').
double ParseNumber(const std::string& field, const std::string& path, int line,
                   const std::string& what);

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

// Reads a run file with `encoder_columns` encoder columns named `column_names` in messages
// ("ticks_right, ticks_left"); `short_row_hint` is added when a row lacks one field.
RunRows ReadRun(const std::string& path, int number, int encoder_columns,
                const std::string& column_names, const std::string& short_row_hint = "");

// One session of a robot: its names, its metadata as the robot reads it, its runs by number.
template <typename Meta, typename Run>
struct Session {
  std::string name;       // directory name, e.g. 221220201643
  std::string path_type;  // parent directory name, e.g. circular, square
  std::string metadata_path;
  Meta metadata;
  std::vector<Run> runs;  // sorted by run number
};

// Reads a session with the robot's readers, read_metadata(path) -> Meta (with num_runs) and
// read_run(path, number, session) -> Run (the session's names and metadata already read), the
// runs in parallel.
template <typename Meta, typename Run, typename ReadMetadataFn, typename ReadRunFn>
Session<Meta, Run> ReadSession(const std::string& directory, ReadMetadataFn read_metadata,
                               ReadRunFn read_run) {
  const SessionFiles files = ListSession(directory);
  Session<Meta, Run> s{
      files.name, files.path_type, files.metadata_path, read_metadata(files.metadata_path), {}};
  CheckRunCount(files, s.metadata.num_runs);
  s.runs.resize(files.runs.size());
  ParallelFor(files.runs.size(), 0, [&](std::size_t i) {
    s.runs[i] = read_run(files.runs[i].second, files.runs[i].first, s);
  });
  return s;
}

// Refuses no session and an `out` the output guard refuses (tools/output_guard.h), then reads
// every session with read(directory): all input is read and checked before anything is written.
void CheckImportArguments(const std::vector<std::string>& session_dirs, const std::string& out,
                          bool force);
template <typename Session, typename ReadFn>
std::vector<Session> ReadSessions(const std::vector<std::string>& session_dirs,
                                  const std::string& out, bool force, ReadFn read) {
  CheckImportArguments(session_dirs, out, force);
  std::vector<Session> sessions;
  for (const std::string& dir : session_dirs) sessions.push_back(read(dir));
  return sessions;
}

// The session whose robot most sessions declare (ties: the earliest); same(a, b) compares two
// sessions' metadata. Some sessions declare perturbed values on purpose (README), the robot is
// the same.
template <typename Session, typename Same>
const Session& MajorityRobot(const std::vector<Session>& sessions, Same same) {
  std::size_t best = 0, best_count = 0;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    std::size_t count = 0;
    for (const Session& s : sessions) count += same(s.metadata, sessions[i].metadata) ? 1 : 0;
    if (count > best_count) best = i, best_count = count;
  }
  return sessions[best];
}

// Refuses sessions whose robot differs from the first session's (same(a, b) compares them).
[[noreturn]] void ThrowNotOneRobot(const std::string& session, const std::string& first);
template <typename Session, typename Same>
void CheckOneRobot(const std::vector<Session>& sessions, Same same) {
  for (const Session& s : sessions) {
    if (!same(s.metadata, sessions.front().metadata)) {
      ThrowNotOneRobot(s.name, sessions.front().name);
    }
  }
}

// Wheel rates over (t(k-1), t(k)]: 2 pi / ticks_per_rev * increment(k) / dt for every column but
// `reading_column` (an angle read at t(k): tricycle steering), which gets the mean of its readings
// at both ends of the interval.
EncoderLog RatesOf(const RunRows& run, double ticks_per_rev, int reading_column = -1);

// A run as fitcal replays it: id `<path type><sep><session><sep>runNN`, trajectory
// `<path type>_<session>` and repetition NN (a robot may relabel), wheel rates (RatesOf), the
// ground truth, and the start pose: the robot is at rest at the start, the ground truth in its
// start frame.
RunLog RunLogOf(const std::string& path_type, const std::string& session, const RunRows& run,
                double ticks_per_rev, int reading_column = -1, char separator = '_');

// The encoder CSV as the robot logged it: `header`, then per row t (`time_decimals` fixed) and
// every column as %.10g; increments are 0 at row 0 (counted before the run), readings as read.
std::string IncrementsCsv(const std::string& header, const RunRows& run, int time_decimals,
                          int reading_column = -1);

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

}  // namespace fitcal::tools::optiodom
