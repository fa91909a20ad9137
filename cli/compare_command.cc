#include "cli/compare_command.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "fit/run_split.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "cli/cli_validators.h"
#include "calibrate/fit_methods.h"
#include "calibrate/method_comparison.h"
#include "calibrate/method_comparison_tables.h"
#include "io/output_guard.h"

namespace fitcal::tools {

namespace {

// Each file as <out><suffix> and how it starts.
constexpr std::pair<const char*, const char*> kOutputFiles[] = {
    {".csv", kComparisonCsvStart},
    {".md", kComparisonMarkdownStart},
    {"_trace.csv", kComparisonTraceStart}};

// A solver flag none of the methods asked for uses (--seed with Ceres methods only, --loss with
// NLopt ones only): refused as fit refuses it, since each fit would run without it.
std::string SolverFlagOfNoMethodAsked(const CompareCommandOptions& options,
                                      const std::vector<const FitMethod*>& methods) {
  bool ceres = false;
  bool nlopt = false;
  std::string names;
  for (const FitMethod* m : methods) {
    (IsCeresMethod(m->name) ? ceres : nlopt) = true;
    names += (names.empty() ? "" : " ") + m->name;
  }
  return SolverFlagThatDoesNotApply(options, CompareCommandOptions(), ceres, nlopt,
                                    "--methods " + names);
}

// What the user typed, checked before any data is read or any fit runs: empty when valid, else
// the one-line reason (exit code 2).
std::string ParseRequest(const CompareCommandOptions& options, ComparisonRequest* r) {
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
  try {
    for (const std::string& text : options.strategies)
      r->strategies.push_back(ParseCompareStrategy(text));
    if (r->methods.empty() || r->strategies.empty() || r->counts.empty() || r->counts.front() < 1) {
      return "need at least one method, one strategy and repetitions >= 1";
    }
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  r->data_name = options.logs;
  r->strategies_given = options.strategies_given;
  if (!options.validation_reps.empty()) {
    r->validation_reps = ParseRepetitionList(options.validation_reps);
  }
  r->threads = options.threads;
  if (std::string e = SolverFlagOfNoMethodAsked(options, r->methods); !e.empty()) return e;
  std::string error;
  if (!MakeFitMethodSettings(options, options.threads, &r->settings, &error)) return error;
  return "";
}

// Each fit's best CF as it improves, then its result, on one line of stderr.
ComparisonProgress ProgressOnStderr() {
  ComparisonProgress p;
  p.during = [](const std::string& label, const NloptProgress& n) {
    std::fprintf(stderr, "\r[%s] %d evaluations, best CF %.5f, %.1f s   ", label.c_str(),
                 n.evaluations, n.best_cf, n.elapsed_s);
    std::fflush(stderr);
  };
  p.done = [](const std::string& label, const ComparisonRow& row) {
    std::fprintf(stderr, "\r[%s] CF %.5f -> validation %.5f, %d evaluations, %.2f s%20s\n",
                 label.c_str(), row.cf_calibration, row.cf_validation, row.evaluations, row.wall_s,
                 "");
  };
  return p;
}

void PrintAndWrite(const CompareCommandOptions& options, const ComparisonRequest& r,
                   const MethodComparison& c, const ParameterDisplay& columns) {
  const std::string markdown = ComparisonMarkdown(c.rows, columns);
  std::string counts;
  for (int k : r.counts) counts += (counts.empty() ? "" : " or ") + std::to_string(k);
  std::printf(
      "Palacin Table 4 on %s: training on the first %s repetition(s) of each strategy's "
      "trajectories, validation on every trajectory of repetitions %s (%zu runs); CF "
      "is Eq. 14 (m and rad)\n\n",
      options.logs.c_str(), counts.c_str(), FormatRepetitionList(c.validation_reps).c_str(),
      c.num_validation);
  if (!r.tying.empty()) {  // what the "(tied)" rows fit
    PrintTying(r.tying);
    std::printf("\n");
  }
  std::printf("%s", markdown.c_str());
  if (!options.no_output) {
    io::WriteFilesAtomically({{options.out + ".csv", ComparisonCsv(c.rows, columns)},
                              {options.out + ".md", markdown},
                              {options.out + "_trace.csv", ComparisonTraceCsv(c.rows)}});
    std::printf("\nwrote %s.csv, %s.md, %s_trace.csv\n", options.out.c_str(), options.out.c_str(),
                options.out.c_str());
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
  CLI::Option* out =
      app.add_option("--out", o.out, "Output prefix: <out>.csv, <out>.md, <out>_trace.csv")
          ->capture_default_str();
  // An --out given with --no-output would be dropped: one of them is a mistake.
  app.add_flag("--no-output", o.no_output, "Print the table only")->excludes(out);
  app.add_flag("--force", o.force, io::kForceFileHelp);
  app.add_flag("--quiet", o.quiet, "No progress on stderr");
  AddSolverOptions(app, o);
  AddTyingFlags(app, o);
}

int RunCompareCommand(const CompareCommandOptions& options) {
  ComparisonRequest request;
  if (const std::string error = ParseRequest(options, &request); !error.empty()) {
    std::cerr << "fitcal compare: " << error << "\n";
    return 2;
  }
  if (!options.quiet && isatty(STDERR_FILENO)) request.progress = ProgressOnStderr();
  return RunReportingErrors("fitcal compare", [&]() -> int {
    if (!options.no_output) {  // before the work: the one overwrite rule, io/output_guard.h
      const std::vector<std::string> inputs = OpenDataset(options).inputs;
      for (const auto& [suffix, start] : kOutputFiles) {
        std::string refusal = io::OutputFileRefusal(options.out + suffix, inputs);
        if (refusal.empty() && !options.force) {
          refusal = io::TextOutputOverwriteRefusal(options.out + suffix, start);
        }
        if (!refusal.empty()) return Refuse(refusal);
      }
    }
    const io::DatasetIndex index = OpenDataset(options).index;
    request.model = ReadRobotModelFile(index.robot_path);
    request.runs = AlignRuns(LoadRuns(options, index, request.model->robot()).runs);
    if (const std::string refusal = ReadTying(options, request.model->robot(), &request.tying);
        !refusal.empty()) {
      std::cerr << "fitcal compare: " << refusal << "\n";
      return 2;
    }
    const MethodComparison comparison = CompareMethods(request);
    if (!comparison.refusal.empty()) {
      std::cerr << "fitcal compare: " << comparison.refusal << "\n";
      return 2;
    }
    PrintAndWrite(options, request, comparison, ComparisonColumns(request.model->robot()));
    return 0;
  });
}

}  // namespace fitcal::tools
