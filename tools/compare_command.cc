#include "tools/compare_command.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "calib/final_pose_cost.h"
#include "calib/run_split.h"
#include "calib/strategies.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/robot_yaml.h"
#include "tools/fit_methods.h"

namespace fitcal::tools {

namespace {

struct Row {
  std::string strategy;
  std::string method;
  int repetitions = 0;  // 0 = the uncalibrated reference row
  Eigen::Matrix3d m_inv = Eigen::Matrix3d::Zero();
  double cf_calibration = NAN;
  double cf_validation = NAN;
  double improvement_percent = NAN;
  int evaluations = 0;
  double wall_s = 0.0;
  std::string termination;
  bool usable = true;
  std::vector<ConvergencePoint> trace;
};

std::string Fixed(double v, int digits) {
  if (std::isnan(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string MatrixText(const Eigen::Matrix3d& m) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out += Fixed(m(r, c), 4) + (c < 2 ? " " : "");
    out += r < 2 ? "; " : "]";
  }
  return out;
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string Csv(const std::vector<Row>& rows) {
  std::ostringstream o;
  o << "strategy,method,repetitions";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) o << ",m_inv_" << r << c;
  }
  o << ",cf_calibration,cf_validation,improvement_percent,evaluations,wall_s,termination,usable\n";
  for (const Row& row : rows) {
    o << CsvField(row.strategy) << "," << row.method << "," << row.repetitions;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) o << "," << (row.repetitions ? Fixed(row.m_inv(r, c), 8) : "");
    }
    o << "," << (std::isnan(row.cf_calibration) ? "" : Fixed(row.cf_calibration, 8)) << ","
      << (std::isnan(row.cf_validation) ? "" : Fixed(row.cf_validation, 8)) << ","
      << (std::isnan(row.improvement_percent) ? "" : Fixed(row.improvement_percent, 3)) << ","
      << row.evaluations << "," << Fixed(row.wall_s, 4) << "," << CsvField(row.termination) << ","
      << (row.usable ? "yes" : "no") << "\n";
  }
  return o.str();
}

std::string Markdown(const std::vector<Row>& rows) {
  std::ostringstream o;
  o << "| Strategy | Method | Reps | M^-1 | CF calibration | CF validation | Improvement | "
       "Evaluations | Wall [s] | Termination |\n"
    << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& row : rows) {
    o << "| " << row.strategy << " | " << row.method << " | "
      << (row.repetitions ? std::to_string(row.repetitions) : "-") << " | "
      << (row.repetitions ? MatrixText(row.m_inv) : "-") << " | " << Fixed(row.cf_calibration, 4)
      << " | " << Fixed(row.cf_validation, 4) << " | "
      << (std::isnan(row.improvement_percent) ? "-" : Fixed(row.improvement_percent, 1) + "%")
      << " | " << (row.repetitions ? std::to_string(row.evaluations) : "-") << " | "
      << (row.repetitions ? Fixed(row.wall_s, 2) : "-") << " | " << row.termination
      << (row.usable ? "" : " (not usable)") << " |\n";
  }
  return o.str();
}

std::string TraceCsv(const std::vector<Row>& rows) {
  std::ostringstream o;
  o << "strategy,method,repetitions,evaluation,best_cf,elapsed_s\n";
  for (const Row& row : rows) {
    for (const ConvergencePoint& p : row.trace) {
      o << CsvField(row.strategy) << "," << row.method << "," << row.repetitions << ","
        << p.evaluation << "," << Fixed(p.best_cf, 10) << "," << Fixed(p.elapsed_s, 4) << "\n";
    }
  }
  return o.str();
}

}  // namespace

int RunCompareCommand(const CompareCommandOptions& options) {
  // Everything the user typed is checked before any data is read or any fit runs.
  std::vector<const FitMethod*> methods;
  for (const std::string& name : options.methods) {
    if (name == "all") {
      for (const FitMethod& m : FitMethods()) methods.push_back(&m);
      continue;
    }
    const FitMethod* m = FindFitMethod(name);
    if (m == nullptr) {
      std::cerr << "fitcal compare: unknown method '" << name
                << "' (available: " << FitMethodNames() << ", all)\n";
      return 2;
    }
    methods.push_back(m);
  }
  std::vector<TrajectoryStrategy> strategies;
  std::vector<int> counts = options.repetitions;
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  FitMethodSettings settings;
  try {
    for (const std::string& text : options.strategies) strategies.push_back(ParseStrategy(text));
    if (methods.empty() || strategies.empty() || counts.empty() || counts.front() < 1) {
      throw std::invalid_argument("need at least one method, one strategy and repetitions >= 1");
    }
    if (options.max_evaluations < 1) throw std::invalid_argument("--max-evaluations must be >= 1");
    settings.objective_set = !options.objective.empty();
    if (settings.objective_set &&
        !ParseFinalPoseObjective(options.objective, &settings.objective)) {
      throw std::invalid_argument("unknown --objective '" + options.objective +
                                  "' (available: squares, eq14)");
    }
  } catch (const std::invalid_argument& e) {
    std::cerr << "fitcal compare: " << e.what() << "\n";
    return 2;
  }
  settings.threads = options.threads;
  settings.seed = options.seed;
  settings.max_evaluations = options.max_evaluations;
  settings.local_polish = options.polish;
  const bool show_progress = !options.quiet && isatty(STDERR_FILENO);

  try {
    io::DatasetOptions dataset_options;
    dataset_options.allow_paths_outside = options.allow_outside_paths;
    dataset_options.num_threads = options.threads;
    const io::Dataset dataset = io::LoadDataset(options.logs, dataset_options);
    const Omni3Robot robot = io::ReadOmni3Robot(dataset.robot_path);
    const std::vector<AlignedRun> runs = AlignRuns(dataset.runs);

    std::set<int> present_set;
    for (const AlignedRun& run : runs) present_set.insert(run.repetition);
    const std::vector<int> present(present_set.begin(), present_set.end());
    if (static_cast<std::size_t>(counts.back()) > present.size()) {
      std::cerr << "fitcal compare: " << options.logs << " has " << present.size()
                << " repetitions; cannot train on " << counts.back() << "\n";
      return 2;
    }
    for (const TrajectoryStrategy& s : strategies) {
      const std::vector<std::string> missing = MissingTrajectories(runs, s);
      if (!missing.empty()) {
        std::string list;
        for (const std::string& label : missing) list += (list.empty() ? "" : ", ") + label;
        std::cerr << "fitcal compare: strategy " << s.name << " needs trajectories the data set "
                  << options.logs << " lacks: " << list
                  << " (choose --strategies from its trajectory labels)\n";
        return 2;
      }
    }
    std::vector<int> validation_reps;
    if (options.validation_reps.empty()) {
      validation_reps.assign(present.begin() + counts.back(), present.end());
    } else {
      validation_reps = ParseRepetitionList(options.validation_reps);
    }
    const std::vector<AlignedRun> validation =
        SplitByRepetition(runs, validation_reps).training;  // every trajectory of those reps
    for (int rep : validation_reps) {
      for (int k : counts) {
        if (std::find(present.begin(), present.begin() + k, rep) != present.begin() + k) {
          std::cerr << "fitcal compare: validation repetition " << rep
                    << " is also a training repetition\n";
          return 2;
        }
      }
    }

    std::vector<Row> rows;
    Row none;
    none.strategy = "All";
    none.method = "None";
    none.cf_validation =
        validation.empty()
            ? NAN
            : EvaluateFinalPoseErrors(robot.nominal.ToArray(), validation, options.threads).cf;
    none.termination = "uncalibrated";
    rows.push_back(none);

    for (const TrajectoryStrategy& strategy : strategies) {
      for (const FitMethod* method : methods) {
        for (int k : counts) {
          const std::vector<int> reps(present.begin(), present.begin() + k);
          const std::vector<AlignedRun> training = SelectRuns(runs, strategy, reps);
          FitMethodSettings s = settings;
          const std::string label = strategy.name + " " + method->name + " x" + std::to_string(k);
          if (show_progress) {
            s.progress = [&label](const NloptProgress& p) {
              std::fprintf(stderr, "\r[%s] %d evaluations, best CF %.5f, %.1f s   ", label.c_str(),
                           p.evaluations, p.best_cf, p.elapsed_s);
              std::fflush(stderr);
            };
          }
          const auto t0 = std::chrono::steady_clock::now();
          const FitMethodOutcome outcome = method->run(training, robot, s);
          Row row;
          row.strategy = strategy.name;
          row.method = method->name;
          row.repetitions = k;
          row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          row.m_inv = omni3::InverseKinematicMatrix(outcome.fit.parameters.data());
          row.cf_calibration =
              EvaluateFinalPoseErrors(outcome.fit.parameters, training, options.threads).cf;
          if (!validation.empty()) {
            row.cf_validation =
                EvaluateFinalPoseErrors(outcome.fit.parameters, validation, options.threads).cf;
            row.improvement_percent =
                100.0 * (none.cf_validation - row.cf_validation) / none.cf_validation;
          }
          row.evaluations = outcome.evaluations;
          row.termination = outcome.fit.termination;
          row.usable = outcome.fit.usable;
          row.trace = outcome.trace;
          if (show_progress) {
            std::fprintf(stderr, "\r[%s] CF %.5f -> validation %.5f, %d evaluations, %.2f s%20s\n",
                         label.c_str(), row.cf_calibration, row.cf_validation, row.evaluations,
                         row.wall_s, "");
          }
          rows.push_back(std::move(row));
        }
      }
    }

    const std::string markdown = Markdown(rows);
    std::printf(
        "Palacin Table 4 on %s: training on the first %s repetition(s) of each strategy's "
        "trajectories, validation on every trajectory of repetitions %s (%zu runs); CF "
        "is Eq. 14 (m and rad)\n\n%s",
        options.logs.c_str(),
        [&] {
          std::string s;
          for (int k : counts) s += (s.empty() ? "" : " or ") + std::to_string(k);
          return s;
        }()
            .c_str(),
        FormatRepetitionList(validation_reps).c_str(), validation.size(), markdown.c_str());
    if (!options.no_output) {
      io::WriteFileAtomically(options.out + ".csv", Csv(rows));
      io::WriteFileAtomically(options.out + ".md", markdown);
      io::WriteFileAtomically(options.out + "_trace.csv", TraceCsv(rows));
      std::printf("\nwrote %s.csv, %s.md, %s_trace.csv\n", options.out.c_str(), options.out.c_str(),
                  options.out.c_str());
    }
    return 0;
  } catch (const std::exception& e) {  // io::InputError too: what() is its file:line message
    std::cerr << "fitcal compare: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
