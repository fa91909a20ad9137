#include "calibrate/generalise_split.h"

#include <cstdio>
#include <map>
#include <set>

namespace fitcal {

namespace {

// The method `fit` uses by default, whose fit the table calls "fit".
constexpr const char* kMethod = "ceres";

// A gate candidate's name as the table writes it ("ceres ..." -> "fit ...").
std::string TableName(const std::string& name) {
  const std::string method = kMethod;
  if (name.compare(0, method.size(), method) != 0) return name;
  return "fit" + name.substr(method.size());
}

// The split as a calibration request: its runs (in the data set's order), its training runs by
// id, fit's defaults (the effects the robot declares refitted, as fit refits them), nothing
// written.
CalibrationRequest SplitRequest(const Robot& robot, const std::vector<RunLog>& logs,
                                const GeneralisationSplit& split, int threads) {
  CalibrationRequest r;
  r.effects_to_fit = robot.effects;
  r.dataset = "split " + split.train_name + " -> " + split.test_name;
  r.method = FindFitMethod(kMethod);
  r.settings.threads = threads;
  r.threads = threads;
  std::set<std::size_t> in_split(split.train.begin(), split.train.end());
  in_split.insert(split.test.begin(), split.test.end());
  for (std::size_t i : in_split) r.runs.push_back(logs.at(i));
  for (std::size_t i : split.train) r.training_ids.push_back(logs.at(i).id);
  r.check_channel_order = false;
  r.will_write = false;
  return r;
}

}  // namespace

SplitCalibration CalibrateSplit(const RobotModelInterface& model, const std::vector<RunLog>& logs,
                                const std::vector<AlignedRun>& runs,
                                const GeneralisationSplit& split, const ModelFitOptions& options,
                                const TrackCandidates& track_candidates,
                                const ParameterTying& tying) {
  SplitCalibration out;
  out.outcome =
      Calibrate(SplitRequest(model.robot(), logs, split, options.ceres.num_threads), model);
  // A refusal before the fit (the data's checks, too few residuals) leaves the table to fit the
  // split itself; its decision line says why `fit` would not.
  const ModelFitResult* fit = out.outcome.candidates.empty() ? nullptr : &out.outcome.fit.fit;
  out.scores = EvaluateSplit(model, runs, split, options, track_candidates, tying, fit);
  return out;
}

std::string DecisionLine(const CalibrationOutcome& outcome) {
  if (outcome.refusal.exit_code != 0) {
    std::string line = "refuses (exit " + std::to_string(outcome.refusal.exit_code) + "):";
    for (std::size_t k = 0; k < outcome.refusal.reasons.size(); ++k) {
      line += (k == 0 ? " " : "; ") + outcome.refusal.reasons[k];
    }
    return line;
  }
  const GateDecision& gate = outcome.gate;
  char cf[80];
  std::snprintf(cf, sizeof cf, "CF %.4f -> %.4f", gate.cf.front(), gate.cf.at(gate.selected));
  return "writes " + TableName(outcome.selected().name) + " (" + gate.judged_on + ": " + cf + ")";
}

std::string FoldDecisionsLine(const std::vector<SplitCalibration>& folds) {
  std::map<std::string, int> count;  // per decision: "refuses (exit 5)", "writes fit", ...
  for (const SplitCalibration& fold : folds) {
    const CalibrationOutcome& o = fold.outcome;
    ++count[o.refusal.exit_code != 0 ? "refuses (exit " + std::to_string(o.refusal.exit_code) + ")"
                                     : "writes " + TableName(o.selected().name)];
  }
  std::string line =
      "fit --residuals final-pose on the " + std::to_string(folds.size()) + " folds:";
  for (const auto& [decision, n] : count) line += " " + decision + " " + std::to_string(n) + ",";
  line.pop_back();
  return line;
}

std::optional<std::vector<std::vector<Segment>>> OptiOdomCheckpoints(
    const std::vector<AlignedRun>& runs, const std::vector<RunLog>& logs) {
  constexpr double kSpacingM = 0.5;
  std::vector<std::vector<Segment>> out;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const GroundTruthTrack& track = logs[i].ground_truth;
    if (track.t_s.size() < 3) return std::nullopt;
    out.push_back(MakeCheckpointsFromStart(runs[i], track, kSpacingM));
  }
  return out;
}

}  // namespace fitcal
