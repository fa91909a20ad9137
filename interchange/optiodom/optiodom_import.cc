#include "interchange/optiodom/optiodom_import.h"

#include <stdexcept>

#include "diagnosis/import_channel_order.h"
#include "interchange/optiodom/optiodom_robots.h"
#include "io/command_failure.h"
#include "io/input_error.h"
#include "io/input_registry.h"
#include "io/output_guard.h"
#include "io/yaml_scalar.h"
#include "odometry/aligned_run.h"
#include "odometry/parallel_for.h"
#include "odometry/pose2.h"
#include "odometry/text_format.h"

namespace fitcal::optiodom {

namespace {

// One session directory before its runs are read: its files, its metadata and the values of the
// robot kind's geometry rows.
struct SessionHead {
  SessionFiles files;
  Metadata metadata;
  std::vector<std::vector<double>> geometry;
};

SessionHead ReadSessionHead(const std::string& directory, const RobotKind& kind) {
  SessionHead s{ListSession(directory), {}, {}};
  s.metadata = ReadMetadata(s.files.metadata_path, kind.type);
  s.metadata.TicksPerWheelRev();  // ngear and encRes are read, and checked, first
  for (const GeometryRow& row : kind.geometry) {
    s.geometry.push_back(s.metadata.Values(row.key, row.count, row.positive));
  }
  CheckRunCount(s.files, s.metadata.NumRuns());
  return s;
}

// The session whose geometry most sessions declare (ties: the earliest).
std::size_t MajoritySession(const std::vector<SessionHead>& sessions) {
  std::size_t best = 0, best_count = 0;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    std::size_t count = 0;
    for (const SessionHead& s : sessions) count += s.geometry == sessions[i].geometry ? 1 : 0;
    if (count > best_count) best = i, best_count = count;
  }
  return best;
}

// "b = 0.205 m, D = 0.084 / 0.084 m".
std::string DescribeGeometry(const RobotKind& kind, const SessionHead& s) {
  std::string out;
  for (std::size_t r = 0; r < s.geometry.size(); ++r) {
    out += (r == 0 ? "" : ", ") + std::string(kind.geometry[r].label) + " =";
    for (std::size_t i = 0; i < s.geometry[r].size(); ++i) {
      out += StrFormat("%s%g", i == 0 ? " " : " / ", s.geometry[r][i]);
    }
    out += " " + std::string(kind.geometry[r].unit);
  }
  return out;
}

// <path><sep><session><sep>runNN.
std::string RunId(const RobotKind& kind, const SessionHead& s, int number) {
  return s.files.path_type + kind.id_separator + s.files.name + kind.id_separator +
         StrFormat("run%02d", number);
}

// A run file to read: its session (index), its number and its path.
struct RunFile {
  std::size_t session;
  int number;
  std::string path;
};

// Refuses a session whose encoders differ from the majority's (robot.yaml holds one
// ticks_per_rev for every ticks CSV); notes the sessions that declare another geometry and the
// runs the authors flagged, which are left out. Returns the run files to read.
std::vector<RunFile> CheckAndNote(const RobotKind& kind, const std::vector<SessionHead>& sessions,
                                  const SessionHead& robot, std::vector<std::string>* notes) {
  std::vector<RunFile> files;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    const SessionHead& s = sessions[i];
    if (s.metadata.TicksPerWheelRev() != robot.metadata.TicksPerWheelRev()) {
      throw io::InputError(
          io::InputErrorKind::kBadValue, s.files.metadata_path, 0,
          "ngear * encRes differs from the other sessions'; import one robot at a time");
    }
    if (s.geometry != robot.geometry) {
      notes->push_back("session " + s.files.path_type + "/" + s.files.name + " declares " +
                       DescribeGeometry(kind, s) + " (the robot YAML keeps the majority's " +
                       DescribeGeometry(kind, robot) + ")");
    }
    for (const auto& [number, path] : s.files.runs) {
      const char* flag = FlaggedRunReason(s.files.path_type, s.files.name, number);
      if (flag != nullptr) {
        notes->push_back("left out " + RunId(kind, s, number) + ": " + flag);
      } else {
        files.push_back({i, number, path});
      }
    }
  }
  return files;
}

// The channel read as an angle at each row (tricycle steering), or -1.
int ReadingColumn(const Robot& robot) {
  for (int j = 0; j < robot.NumChannels(); ++j) {
    if (robot.channels[j].kind == ChannelKind::kAngle) return j;
  }
  return -1;
}

// Each session's place among the sessions of its path type, by name (timestamps: 1 = earliest).
int SessionPlace(const std::vector<SessionHead>& sessions, const SessionHead& s) {
  int earlier = 0;
  for (const SessionHead& other : sessions) {
    earlier += other.files.path_type == s.files.path_type && other.files.name < s.files.name;
  }
  return earlier + 1;
}

// Reads one run file in our channel signs; an angle column must hold readings in rad.
RunRows ReadRunRows(const RobotKind& kind, const RunFile& file, int reading_column) {
  RunRows run = ReadRun(file.path, file.number, kind.file_columns);
  std::vector<double> readings;
  for (std::vector<double>& row : run.encoder) {
    for (std::size_t j = 0; j < row.size(); ++j) {
      if (static_cast<int>(j) == reading_column) {
        readings.push_back(row[j]);
      } else {
        row[j] = kind.tick_sign * row[j] + 0.0;  // + 0.0 keeps a flipped 0 at 0
      }
    }
  }
  if (reading_column >= 0 && kind.check_readings != nullptr)
    kind.check_readings(readings, file.path, run.first_line);
  return run;
}

// The run's id, trajectory and repetition as the robot kind labels them.
void Label(const RobotKind& kind, const std::vector<SessionHead>& sessions, const RunFile& file,
           RunLog* log) {
  const SessionHead& s = sessions[file.session];
  log->id = RunId(kind, s, file.number);
  log->trajectory = s.files.path_type + kind.trajectory_separator + s.files.name;
  log->repetition = file.number;
  if (kind.label_by_direction) {
    const auto& track = log->ground_truth.world_T_robot;
    const double turn_rad = track.back().theta - track.front().theta;
    log->trajectory = s.files.path_type + (turn_rad < 0.0 ? "_cw" : "_ccw");
    log->repetition = SessionPlace(sessions, s);
  }
}

}  // namespace

OptiOdomImport ReadOptiOdomSessions(const std::vector<std::string>& session_dirs) {
  if (session_dirs.empty()) {
    throw std::invalid_argument("import needs at least one OptiOdom session directory");
  }
  const RobotKind& kind = RobotKindOf(SessionType(session_dirs.front()), session_dirs.front());
  std::vector<SessionHead> sessions;
  for (const std::string& dir : session_dirs) sessions.push_back(ReadSessionHead(dir, kind));
  const SessionHead& robot = sessions[MajoritySession(sessions)];
  OptiOdomImport in;
  in.kind = &kind;
  in.num_sessions = static_cast<int>(sessions.size());
  in.model = kind.nominal_model(robot.metadata);
  const std::vector<RunFile> files = CheckAndNote(kind, sessions, robot, &in.notes);
  const int reading_column = ReadingColumn(in.model->robot());
  in.rows.resize(files.size());
  in.runs.resize(files.size());
  ParallelFor(files.size(), 0, [&](std::size_t i) {
    in.rows[i] = ReadRunRows(kind, files[i], reading_column);
    in.runs[i] = RunLogOf(in.rows[i], robot.metadata.TicksPerWheelRev(), reading_column);
    Label(kind, sessions, files[i], &in.runs[i]);
    if (!in.model->robot().encoder) in.rows[i] = {};  // written from runs (omni4: -130 MB)
  });
  return in;
}

namespace {

// Ticks as logged when the robot counts ticks, else the rates exactly (optiodom_format.h).
DatasetText DatasetTextOf(const OptiOdomImport& in) {
  const Robot& robot = in.model->robot();
  DatasetText text;
  text.encoder_csv = [&in, &robot](std::size_t i) {
    return robot.encoder ? TicksCsv(robot, in.rows[i], in.kind->time_decimals, ReadingColumn(robot))
                         : ExactRatesCsv(robot, in.runs[i]);
  };
  if (!robot.encoder) text.ground_truth_csv = ExactGroundTruthCsv;
  if (in.kind->file_comment != nullptr) {
    text.header = in.kind->file_comment;
    for (const std::string& n : in.notes) text.header += "# " + io::YamlCommentText(n) + "\n";
  }
  return text;
}

// Refuses sessions of two robots, and an `out` that would replace, hold or sit inside a recording
// (the recordings are inputs) or that the overwrite rule refuses.
void CheckSessionsAndOut(const ImportOptiOdomOptions& options) {
  if (options.sessions.empty()) {
    throw UsageError("import optiodom needs at least one session directory");
  }
  // A type no OptiOdom robot has is that session's own error (RobotKindOf throws naming it), not
  // a mismatch blamed on the sessions after it.
  const RobotKind* first = nullptr;
  for (const std::string& dir : options.sessions) {
    const RobotKind& kind = RobotKindOf(SessionType(dir), dir);
    if (first == nullptr) first = &kind;
    if (&kind != first) {
      throw UsageError(dir + ": a " + kind.type + " session among " + first->type +
                       " sessions; import one robot at a time");
    }
  }
  for (const std::string& dir : options.sessions) io::RegisterInput(dir);
  if (const std::string refusal = io::DirectoryOutputRefusal(options.out, io::kDatasetKind,
                                                             options.force, options.sessions);
      !refusal.empty()) {
    throw UsageError(refusal);
  }
}

}  // namespace

OptiOdomImport ImportOptiOdom(const ImportOptiOdomOptions& options,
                              const std::function<void(const std::string&)>& say) {
  CheckSessionsAndOut(options);
  OptiOdomImport in = ReadOptiOdomSessions(options.sessions);
  const auto tell = [&say](const std::string& line) {
    if (say) say(line);
  };
  for (const std::string& note : in.notes) tell(note);
  CheckUniqueRunIds(in.runs, options.out);
  in.channel_order = CheckImportedChannelOrder(in.runs, *in.model, options.skip_mapping_check);
  tell(in.channel_order);
  in.nominal = EvaluateFinalPoseErrors(*in.model, in.model->robot().nominal, AlignRuns(in.runs));
  WriteDataset(in.runs, *in.model, DatasetTextOf(in), options.out, options.force,
               options.sessions);
  return in;
}

std::string ImportSummary(const OptiOdomImport& in, const std::string& out) {
  return StrFormat(
      "wrote %zu runs of %d sessions to %s; nominal CF (Eq. 14) %.4f, mean final position "
      "error %.4f m, heading %.3f deg",
      in.runs.size(), in.num_sessions, out.c_str(), in.nominal.cf,
      in.nominal.mean_position_error_m, RadToDeg(in.nominal.mean_abs_heading_error_rad));
}

}  // namespace fitcal::optiodom
