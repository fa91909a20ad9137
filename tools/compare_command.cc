#include "tools/compare_command.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "fit/final_pose_errors.h"
#include "fit/run_split.h"
#include "fit/strategies.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "models/model_registry.h"
#include "tools/cli_validators.h"
#include "calibrate/fit_methods.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

namespace {

struct Row {
  std::string strategy;
  std::string method;
  int repetitions = 0;             // 0 = the uncalibrated reference row
  std::vector<double> parameters;  // empty for the uncalibrated reference row
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

// How a row's parameters are shown: as the model registers it (ModelExtras::display: omni3 as
// the M^-1 of Palacin Eq. 6), else its parameters in display units (m, deg).
using ParameterColumns = ParameterDisplay;

ParameterColumns ColumnsFor(const Robot& robot) {
  ParameterColumns c;
  if (const auto& display = ExtrasOf(robot.model).display) return display(robot);
  c.markdown_header = "Parameters";
  for (const ParameterInfo& info : robot.parameters) {
    c.csv_names.push_back(info.KeyName());
  }
  c.csv_values = [robot](const std::vector<double>& p) {
    std::vector<double> out;
    for (int k = 0; k < robot.NumParameters(); ++k) {
      out.push_back(p[k] * robot.parameters[k].DisplayScale());
    }
    return out;
  };
  c.markdown = [robot](const std::vector<double>& p) {
    std::string out;
    char item[96];
    for (int k = 0; k < robot.NumParameters(); ++k) {
      const ParameterInfo& info = robot.parameters[k];
      std::snprintf(item, sizeof item, "%s%s %.6g%s", out.empty() ? "" : ", ", info.name.c_str(),
                    p[k] * info.DisplayScale(), info.unit == ParameterUnit::kAngle ? " deg" : "");
      out += item;
    }
    return out;
  };
  return c;
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// How each of compare's files starts, whatever the model: how a later run recognises them as its
// own previous output (tools/output_guard.h, rule 1).
constexpr char kCsvStart[] = "strategy,method,repetitions,";
constexpr char kMarkdownStart[] = "| Strategy | Method | Reps | ";
constexpr char kTraceStart[] = "strategy,method,repetitions,evaluation,best_cf,elapsed_s";
// Each file as <out><suffix> and how it starts.
constexpr std::pair<const char*, const char*> kOutputFiles[] = {
    {".csv", kCsvStart}, {".md", kMarkdownStart}, {"_trace.csv", kTraceStart}};

std::string Csv(const std::vector<Row>& rows, const ParameterColumns& columns) {
  std::ostringstream o;
  o << "strategy,method,repetitions";
  for (const std::string& name : columns.csv_names) o << "," << name;
  o << ",cf_calibration,cf_validation,improvement_percent,evaluations,wall_s,termination,usable\n";
  for (const Row& row : rows) {
    o << CsvField(row.strategy) << "," << row.method << "," << row.repetitions;
    const std::vector<double> values =
        row.parameters.empty() ? std::vector<double>() : columns.csv_values(row.parameters);
    for (std::size_t c = 0; c < columns.csv_names.size(); ++c) {
      o << "," << (values.empty() ? "" : Fixed(values[c], 8));
    }
    o << "," << (std::isnan(row.cf_calibration) ? "" : Fixed(row.cf_calibration, 8)) << ","
      << (std::isnan(row.cf_validation) ? "" : Fixed(row.cf_validation, 8)) << ","
      << (std::isnan(row.improvement_percent) ? "" : Fixed(row.improvement_percent, 3)) << ","
      << row.evaluations << "," << Fixed(row.wall_s, 4) << "," << CsvField(row.termination) << ","
      << (row.usable ? "yes" : "no") << "\n";
  }
  return o.str();
}

std::string Markdown(const std::vector<Row>& rows, const ParameterColumns& columns) {
  std::ostringstream o;
  o << kMarkdownStart << columns.markdown_header
    << " | CF calibration | CF validation | Improvement | "
       "Evaluations | Wall [s] | Termination |\n"
    << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& row : rows) {
    o << "| " << row.strategy << " | " << row.method << " | "
      << (row.repetitions ? std::to_string(row.repetitions) : "-") << " | "
      << (row.parameters.empty() ? "-" : columns.markdown(row.parameters)) << " | "
      << Fixed(row.cf_calibration, 4) << " | " << Fixed(row.cf_validation, 4) << " | "
      << (std::isnan(row.improvement_percent) ? "-" : Fixed(row.improvement_percent, 1) + "%")
      << " | " << (row.repetitions ? std::to_string(row.evaluations) : "-") << " | "
      << (row.repetitions ? Fixed(row.wall_s, 2) : "-") << " | " << row.termination
      << (row.usable ? "" : " (not usable)") << " |\n";
  }
  return o.str();
}

std::string TraceCsv(const std::vector<Row>& rows) {
  std::ostringstream o;
  o << kTraceStart << "\n";
  for (const Row& row : rows) {
    for (const ConvergencePoint& p : row.trace) {
      o << CsvField(row.strategy) << "," << row.method << "," << row.repetitions << ","
        << p.evaluation << "," << Fixed(p.best_cf, 10) << "," << Fixed(p.elapsed_s, 4) << "\n";
    }
  }
  return o.str();
}

// The robot and runs of a data set, loaded through the model's own robot description like every
// other command's; every model fits and is scored through the seam (calibrate/fit_methods.h,
// fit/final_pose_errors.h).
struct CompareData {
  RobotModelPtr model;
  std::vector<AlignedRun> runs;

  double Cf(const std::vector<double>& p, const std::vector<AlignedRun>& on, int threads) const {
    return EvaluateFinalPoseErrors(*model, p, on, threads).cf;
  }
};

CompareData LoadCompareData(const CompareCommandOptions& options) {
  const io::DatasetIndex index = OpenDataset(options).index;
  CompareData d;
  d.model = ReadRobotModelFile(index.robot_path);
  d.runs = AlignRuns(LoadRuns(options, index, d.model->robot()).runs);
  return d;
}

struct FitOutcome {
  std::vector<double> parameters;
  int evaluations = 0;
  std::string termination;
  bool usable = false;
  std::vector<ConvergencePoint> trace;
};

FitOutcome RunMethod(const FitMethod& method, const std::vector<AlignedRun>& training,
                     const CompareData& d, const FitMethodSettings& s) {
  const ModelFitMethodOutcome o = method.run_model(training, *d.model, s);
  return {o.fit.parameters, o.evaluations, o.fit.termination, o.fit.usable, o.trace};
}

// "all" (every trajectory of the data set) and "<prefix>*" (the labels starting with prefix, e.g.
// "circular/*") are resolved against the runs; anything else is fit/strategies.h's.
TrajectoryStrategy ParseCompareStrategy(const std::string& text) {
  if (text == "all" || (!text.empty() && text.back() == '*')) return {text, {}};
  return ParseStrategy(text);
}

void ResolveStrategy(const std::vector<AlignedRun>& runs, TrajectoryStrategy* s) {
  if (!s->labels.empty()) return;
  const std::string prefix = s->name == "all" ? "" : s->name.substr(0, s->name.size() - 1);
  for (const AlignedRun& run : runs) {
    if (run.trajectory.compare(0, prefix.size(), prefix) == 0 &&
        std::find(s->labels.begin(), s->labels.end(), run.trajectory) == s->labels.end()) {
      s->labels.push_back(run.trajectory);
    }
  }
  if (s->labels.empty()) {
    throw std::invalid_argument("strategy " + s->name + " matches no trajectory of the data set");
  }
}

// Palacin's STA..STE need the flower's labels. Without --strategies, keep those the data set has
// (the flower of omni3 and the omni model's generalised flower have them all) or, when it has
// none, train on every trajectory ("all": the split is by repetitions only).
std::vector<TrajectoryStrategy> DefaultStrategiesFor(const std::vector<AlignedRun>& runs,
                                                     std::vector<TrajectoryStrategy> strategies) {
  std::vector<TrajectoryStrategy> present;
  for (const TrajectoryStrategy& s : strategies) {
    if (s.labels.empty() || MissingTrajectories(runs, s).empty()) present.push_back(s);
  }
  if (present.empty()) present.push_back({"all", {}});
  return present;
}

// One row per closed-form calibration of the model (e.g. UMBmark) on these training runs.
void AddClosedFormRows(const CompareData& d, const std::string& strategy, int k,
                       const std::vector<AlignedRun>& training,
                       const std::vector<AlignedRun>& validation, double cf_nominal, int threads,
                       std::vector<Row>* rows) {
  for (const ClosedFormCalibration& c : d.model->ClosedForms(training)) {
    Row row;
    row.strategy = strategy;
    row.method = c.method;
    row.repetitions = k;
    row.parameters = c.parameters;
    row.cf_calibration = d.Cf(c.parameters, training, threads);
    if (!validation.empty()) {
      row.cf_validation = d.Cf(c.parameters, validation, threads);
      row.improvement_percent = 100.0 * (cf_nominal - row.cf_validation) / cf_nominal;
    }
    row.termination = "closed form";
    rows->push_back(std::move(row));
  }
}

// What the user typed, checked before any data is read or any fit runs.
struct CompareRequest {
  std::vector<const FitMethod*> methods;
  std::vector<TrajectoryStrategy> strategies;
  std::vector<int> counts;  // training repetitions k, sorted, unique
  FitMethodSettings settings;
};

// Empty when valid, else the one-line reason (exit code 2).
std::string ParseRequest(const CompareCommandOptions& options, CompareRequest* r) {
  for (const std::string& name : options.methods) {
    if (name == "all") {
      for (const FitMethod& m : FitMethods()) r->methods.push_back(&m);
      continue;
    }
    const FitMethod* m = FindFitMethod(name);
    if (m == nullptr) {
      return "unknown method '" + name + "' (available: " + FitMethodNames() + ", all)";
    }
    r->methods.push_back(m);
  }
  r->counts = options.repetitions;
  std::sort(r->counts.begin(), r->counts.end());
  r->counts.erase(std::unique(r->counts.begin(), r->counts.end()), r->counts.end());
  FitMethodSettings& settings = r->settings;
  try {
    for (const std::string& text : options.strategies)
      r->strategies.push_back(ParseCompareStrategy(text));
    if (r->methods.empty() || r->strategies.empty() || r->counts.empty() || r->counts.front() < 1) {
      return "need at least one method, one strategy and repetitions >= 1";
    }
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  std::string error;
  if (!MakeFitMethodSettings(options, options.threads, &settings, &error)) return error;
  return "";
}

// The repetitions present, the validation repetitions, and the check that no validation
// repetition trains; empty when fine, else the one-line reason (exit code 2).
std::string SplitRepetitions(const CompareCommandOptions& options, const CompareRequest& r,
                             const std::vector<AlignedRun>& runs, std::vector<int>* present,
                             std::vector<int>* validation_reps) {
  std::set<int> present_set;
  for (const AlignedRun& run : runs) present_set.insert(run.repetition);
  present->assign(present_set.begin(), present_set.end());
  if (static_cast<std::size_t>(r.counts.back()) > present->size()) {
    return options.logs + " has " + std::to_string(present->size()) +
           " repetitions; cannot train on " + std::to_string(r.counts.back());
  }
  for (const TrajectoryStrategy& s : r.strategies) {
    const std::vector<std::string> missing = MissingTrajectories(runs, s);
    if (missing.empty()) continue;
    std::string list;
    for (const std::string& label : missing) list += (list.empty() ? "" : ", ") + label;
    return "strategy " + s.name + " needs trajectories the data set " + options.logs +
           " lacks: " + list + " (choose --strategies from its trajectory labels)";
  }
  if (options.validation_reps.empty()) {
    validation_reps->assign(present->begin() + r.counts.back(), present->end());
  } else {
    *validation_reps = ParseRepetitionList(options.validation_reps);
  }
  for (int rep : *validation_reps) {
    for (int k : r.counts) {
      if (std::find(present->begin(), present->begin() + k, rep) != present->begin() + k) {
        return "validation repetition " + std::to_string(rep) + " is also a training repetition";
      }
    }
  }
  return "";
}

// `name`: the method's, or "<method> (tied)" for its fit of the reduced model (s.tying).
Row FitRow(const FitMethod& method, const std::string& name, const std::string& strategy, int k,
           const std::vector<AlignedRun>& training, const std::vector<AlignedRun>& validation,
           double cf_nominal, const CompareData& d, FitMethodSettings s, bool show_progress,
           int threads) {
  const std::string label = strategy + " " + name + " x" + std::to_string(k);
  if (show_progress) {
    s.progress = [&label](const NloptProgress& p) {
      std::fprintf(stderr, "\r[%s] %d evaluations, best CF %.5f, %.1f s   ", label.c_str(),
                   p.evaluations, p.best_cf, p.elapsed_s);
      std::fflush(stderr);
    };
  }
  const auto t0 = std::chrono::steady_clock::now();
  const FitOutcome outcome = RunMethod(method, training, d, s);
  Row row;
  row.strategy = strategy;
  row.method = name;
  row.repetitions = k;
  row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row.parameters = outcome.parameters;
  row.cf_calibration = d.Cf(outcome.parameters, training, threads);
  if (!validation.empty()) {
    row.cf_validation = d.Cf(outcome.parameters, validation, threads);
    row.improvement_percent = 100.0 * (cf_nominal - row.cf_validation) / cf_nominal;
  }
  row.evaluations = outcome.evaluations;
  row.termination = outcome.termination;
  row.usable = outcome.usable;
  row.trace = outcome.trace;
  if (show_progress) {
    std::fprintf(stderr, "\r[%s] CF %.5f -> validation %.5f, %d evaluations, %.2f s%20s\n",
                 label.c_str(), row.cf_calibration, row.cf_validation, row.evaluations, row.wall_s,
                 "");
  }
  return row;
}

void PrintAndWrite(const CompareCommandOptions& options, const CompareRequest& r,
                   const std::vector<int>& validation_reps, std::size_t num_validation,
                   const std::vector<Row>& rows, const ParameterColumns& columns,
                   const ParameterTying& tying) {
  const std::string markdown = Markdown(rows, columns);
  std::string counts;
  for (int k : r.counts) counts += (counts.empty() ? "" : " or ") + std::to_string(k);
  std::printf(
      "Palacin Table 4 on %s: training on the first %s repetition(s) of each strategy's "
      "trajectories, validation on every trajectory of repetitions %s (%zu runs); CF "
      "is Eq. 14 (m and rad)\n\n",
      options.logs.c_str(), counts.c_str(), FormatRepetitionList(validation_reps).c_str(),
      num_validation);
  if (!tying.empty()) {  // what the "(tied)" rows fit
    PrintTying(tying);
    std::printf("\n");
  }
  std::printf("%s", markdown.c_str());
  if (!options.no_output) {
    io::WriteFilesAtomically({{options.out + ".csv", Csv(rows, columns)},
                              {options.out + ".md", markdown},
                              {options.out + "_trace.csv", TraceCsv(rows)}});
    std::printf("\nwrote %s.csv, %s.md, %s_trace.csv\n", options.out.c_str(), options.out.c_str(),
                options.out.c_str());
  }
}

// For every strategy and training count k: the closed forms' rows, then each method's fit and,
// with a tying, its fit of the reduced model right after it ("<method> (tied)").
void AddStrategyRows(const CompareRequest& request, const CompareData& d,
                     const std::vector<int>& present, const std::vector<AlignedRun>& validation,
                     const ParameterTying& tying, bool show_progress, int threads,
                     std::vector<Row>* rows) {
  const double cf_nominal = rows->front().cf_validation;  // the uncalibrated reference row
  FitMethodSettings tied = request.settings;
  tied.tying = tying;
  for (const TrajectoryStrategy& strategy : request.strategies) {
    for (int k : request.counts) {
      const std::vector<int> reps(present.begin(), present.begin() + k);
      const std::vector<AlignedRun> training = SelectRuns(d.runs, strategy, reps);
      AddClosedFormRows(d, strategy.name, k, training, validation, cf_nominal, threads, rows);
    }
    for (const FitMethod* method : request.methods) {
      for (int k : request.counts) {
        const std::vector<int> reps(present.begin(), present.begin() + k);
        const std::vector<AlignedRun> training = SelectRuns(d.runs, strategy, reps);
        rows->push_back(FitRow(*method, method->name, strategy.name, k, training, validation,
                               cf_nominal, d, request.settings, show_progress, threads));
        if (tying.empty()) continue;
        rows->push_back(FitRow(*method, method->name + " (tied)", strategy.name, k, training,
                               validation, cf_nominal, d, tied, show_progress, threads));
      }
    }
  }
}

}  // namespace

void AddCompareOptions(CLI::App& app, CompareCommandOptions& o) {
  AddDatasetOptions(app, o);
  // A data set takes the STA..STE it has unless --strategies names some.
  app.callback([&app, &o] { o.strategies_given = app.count("--strategies") > 0; });
  app.add_option("--strategies", o.strategies,
                 "STA..STE, trajectory lists such as R1,R5,G4 or B1-B12, all, or a label "
                 "prefix such as circular/* (one per item)")
      ->capture_default_str();
  app.add_option("--methods", o.methods, "Methods (" + FitMethodNames() + ") or all")
      ->capture_default_str();
  app.add_option("--repetitions", o.repetitions, "Train on the first k repetitions, for each k")
      ->capture_default_str();
  app.add_option("--validation-reps", o.validation_reps,
                 "Validation repetitions (default: those after the largest k)")
      ->check(RepetitionListValidator());
  app.add_option("--out", o.out, "Output prefix: <out>.csv, <out>.md, <out>_trace.csv")
      ->capture_default_str();
  app.add_flag("--no-output", o.no_output, "Print the table only");
  app.add_flag("--force", o.force, kForceFileHelp);
  app.add_flag("--quiet", o.quiet, "No progress on stderr");
  AddSolverOptions(app, o);
  AddTyingFlags(app, o);
}

int RunCompareCommand(const CompareCommandOptions& options) {
  CompareRequest request;
  if (const std::string error = ParseRequest(options, &request); !error.empty()) {
    std::cerr << "fitcal compare: " << error << "\n";
    return 2;
  }
  const bool show_progress = !options.quiet && isatty(STDERR_FILENO);
  return RunReportingErrors("fitcal compare", [&]() -> int {
    if (!options.no_output) {  // before the work: the one overwrite rule, tools/output_guard.h
      const std::vector<std::string> inputs = OpenDataset(options).inputs;
      for (const auto& [suffix, start] : kOutputFiles) {
        std::string refusal = OutputFileRefusal(options.out + suffix, inputs);
        if (refusal.empty() && !options.force) {
          refusal = TextOutputOverwriteRefusal(options.out + suffix, start);
        }
        if (!refusal.empty()) return Refuse(refusal);
      }
    }
    const CompareData d = LoadCompareData(options);
    ParameterTying tying;
    if (const std::string refusal = ReadTying(options, d.model->robot(), &tying);
        !refusal.empty()) {
      std::cerr << "fitcal compare: " << refusal << "\n";
      return 2;
    }
    if (!options.strategies_given) {
      request.strategies = DefaultStrategiesFor(d.runs, request.strategies);
    }
    for (TrajectoryStrategy& s : request.strategies) ResolveStrategy(d.runs, &s);
    std::vector<int> present, validation_reps;
    if (const std::string error =
            SplitRepetitions(options, request, d.runs, &present, &validation_reps);
        !error.empty()) {
      std::cerr << "fitcal compare: " << error << "\n";
      return 2;
    }
    const std::vector<AlignedRun> validation =
        SplitByRepetition(d.runs, validation_reps).training;  // every trajectory of those reps

    std::vector<Row> rows;
    Row none;
    none.strategy = "All";
    none.method = "None";
    none.cf_validation =
        validation.empty() ? NAN : d.Cf(d.model->robot().nominal, validation, options.threads);
    none.termination = "uncalibrated";
    rows.push_back(none);
    AddStrategyRows(request, d, present, validation, tying, show_progress, options.threads, &rows);
    PrintAndWrite(options, request, validation_reps, validation.size(), rows,
                  ColumnsFor(d.model->robot()), tying);
    return 0;
  });
}

}  // namespace fitcal::tools
