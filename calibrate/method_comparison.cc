#include "calibrate/method_comparison.h"

#include <algorithm>
#include <chrono>
#include <set>
#include <stdexcept>
#include <utility>

#include "fit/final_pose_errors.h"
#include "fit/run_split.h"
#include "io/text_file.h"

namespace fitcal {

namespace {

double Cf(const ComparisonRequest& r, const std::vector<double>& p,
          const std::vector<AlignedRun>& on) {
  return EvaluateFinalPoseErrors(*r.model, p, on, r.threads).cf;
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
void AddClosedFormRows(const ComparisonRequest& r, const std::string& strategy, int k,
                       const std::vector<AlignedRun>& training,
                       const std::vector<AlignedRun>& validation, double cf_nominal,
                       std::vector<ComparisonRow>* rows) {
  for (const ClosedFormCalibration& c : r.model->ClosedForms(training)) {
    ComparisonRow row;
    row.strategy = strategy;
    row.method = c.method;
    row.repetitions = k;
    row.parameters = c.parameters;
    row.cf_calibration = Cf(r, c.parameters, training);
    if (!validation.empty()) {
      row.cf_validation = Cf(r, c.parameters, validation);
      row.improvement_percent = 100.0 * (cf_nominal - row.cf_validation) / cf_nominal;
    }
    row.termination = "closed form";
    rows->push_back(std::move(row));
  }
}

// The repetitions present, the validation repetitions, and the check that no validation
// repetition trains; empty when fine, else the one-line reason.
std::string SplitRepetitions(const ComparisonRequest& r, std::vector<int>* present,
                             std::vector<int>* validation_reps) {
  std::set<int> present_set;
  for (const AlignedRun& run : r.runs) present_set.insert(run.repetition);
  present->assign(present_set.begin(), present_set.end());
  if (static_cast<std::size_t>(r.counts.back()) > present->size()) {
    return r.data_name + " has " + std::to_string(present->size()) +
           " repetitions; cannot train on " + std::to_string(r.counts.back());
  }
  for (const TrajectoryStrategy& s : r.strategies) {
    const std::vector<std::string> missing = MissingTrajectories(r.runs, s);
    if (missing.empty()) continue;
    return "strategy " + s.name + " needs trajectories the data set " + r.data_name +
           " lacks: " + io::Joined(missing, ", ") +
           " (choose --strategies from its trajectory labels)";
  }
  if (r.validation_reps.empty()) {
    validation_reps->assign(present->begin() + r.counts.back(), present->end());
  } else {
    *validation_reps = r.validation_reps;
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
ComparisonRow FitRow(const ComparisonRequest& r, const FitMethod& method, const std::string& name,
                     const std::string& strategy, int k, const std::vector<AlignedRun>& training,
                     const std::vector<AlignedRun>& validation, double cf_nominal,
                     FitMethodSettings s) {
  const std::string label = strategy + " " + name + " x" + std::to_string(k);
  if (r.progress.during) {
    s.progress = [&r, &label](const NloptProgress& p) { r.progress.during(label, p); };
  }
  const auto t0 = std::chrono::steady_clock::now();
  const ModelFitMethodOutcome outcome = method.run_model(training, *r.model, s);
  ComparisonRow row;
  row.strategy = strategy;
  row.method = name;
  row.repetitions = k;
  row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row.parameters = outcome.fit.parameters;
  row.cf_calibration = Cf(r, row.parameters, training);
  if (!validation.empty()) {
    row.cf_validation = Cf(r, row.parameters, validation);
    row.improvement_percent = 100.0 * (cf_nominal - row.cf_validation) / cf_nominal;
  }
  row.evaluations = outcome.evaluations;
  row.termination = outcome.fit.termination;
  row.usable = outcome.fit.usable;
  row.trace = outcome.trace;
  if (r.progress.done) r.progress.done(label, row);
  return row;
}

// For every strategy and training count k: the closed forms' rows, then each method's fit and,
// with a tying, its fit of the reduced model right after it ("<method> (tied)").
void AddStrategyRows(const ComparisonRequest& r, const std::vector<int>& present,
                     const std::vector<AlignedRun>& validation, std::vector<ComparisonRow>* rows) {
  const double cf_nominal = rows->front().cf_validation;  // the uncalibrated reference row
  FitMethodSettings tied = r.settings;
  tied.tying = r.tying;
  for (const TrajectoryStrategy& strategy : r.strategies) {
    for (int k : r.counts) {
      const std::vector<int> reps(present.begin(), present.begin() + k);
      const std::vector<AlignedRun> training = SelectRuns(r.runs, strategy, reps);
      AddClosedFormRows(r, strategy.name, k, training, validation, cf_nominal, rows);
    }
    for (const FitMethod* method : r.methods) {
      for (int k : r.counts) {
        const std::vector<int> reps(present.begin(), present.begin() + k);
        const std::vector<AlignedRun> training = SelectRuns(r.runs, strategy, reps);
        rows->push_back(FitRow(r, *method, method->name, strategy.name, k, training, validation,
                               cf_nominal, r.settings));
        if (r.tying.empty()) continue;
        rows->push_back(FitRow(r, *method, method->name + " (tied)", strategy.name, k, training,
                               validation, cf_nominal, tied));
      }
    }
  }
}

}  // namespace

TrajectoryStrategy ParseCompareStrategy(const std::string& text) {
  if (text == "all" || (!text.empty() && text.back() == '*')) return {text, {}};
  return ParseStrategy(text);
}

MethodComparison CompareMethods(ComparisonRequest r) {
  if (!r.strategies_given) r.strategies = DefaultStrategiesFor(r.runs, r.strategies);
  for (TrajectoryStrategy& s : r.strategies) ResolveStrategy(r.runs, &s);
  MethodComparison out;
  std::vector<int> present;
  out.refusal = SplitRepetitions(r, &present, &out.validation_reps);
  if (!out.refusal.empty()) return out;
  // Every trajectory of the validation repetitions.
  const std::vector<AlignedRun> validation =
      SplitByRepetition(r.runs, out.validation_reps).training;
  out.num_validation = validation.size();
  ComparisonRow none;
  none.strategy = "All";
  none.method = "None";
  none.cf_validation = validation.empty() ? NAN : Cf(r, r.model->robot().nominal, validation);
  none.termination = "uncalibrated";
  out.rows.push_back(none);
  AddStrategyRows(r, present, validation, &out.rows);
  return out;
}

}  // namespace fitcal
