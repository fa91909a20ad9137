#include "calibrate/diagnose_page_builder.h"

#include <cmath>

#include "fitcal/version.h"
#include "odometry/text_format.h"
#include "validation/report_builder.h"
#include "validation/trajectory_metrics.h"

namespace fitcal {

namespace {

std::string Format(const char* format, double v) { return FormatDouble(format, v); }

// The verdict of the page: effects named as causes, effects that only describe part of a
// structure, structure and no effect, or nothing at all.
void SetConclusion(const DiagnoseResult& r, io::DiagnosePageData* page) {
  const bool any_effect = !r.final_fit.effects.empty();
  if (r.effects_named) {
    page->level = "EFFECTS_NAMED";
    page->conclusion = "The residual is explained by the effect(s) accepted below; nothing "
                       "structured remains.";
  } else if (any_effect) {
    page->level = "PARTIAL";
    page->conclusion = "Effects were accepted, but structure remains: they describe part of it "
                       "and may stand in for an effect outside the library.";
  } else if (r.unexplained_structure) {
    page->level = "UNEXPLAINED";
    page->conclusion = "The residual has structure that no candidate effect explains.";
  } else {
    page->level = "NOTHING_FOUND";
    page->conclusion = "No structure beyond the noise and no effect that earns its place: the "
                       "model's parameters are enough for these runs.";
  }
}

void AddStructureTests(const DiagnoseResult& r, io::DiagnosePageData* page) {
  const auto lof = [&](const char* name, const LackOfFit& l) {
    if (!l.available) return;
    page->structure.push_back(
        {name, "F = " + Format("%.2f", l.f) + " on (" + Format("%.0f", l.df_lof) + ", " +
                   Format("%.0f", l.df_pe) + ") dof",
         l.p_value, l.p_value < kLofAlpha,
         "the repetitions of a trajectory agree with each other better than with the model"});
  };
  lof("lack of fit, declared fit", r.before.lack_of_fit);
  lof("lack of fit, final model", r.after.lack_of_fit);
  const SensorFloorTest& floor = r.after.sensor_floor;
  if (floor.available) {
    page->structure.push_back({"residual against the sensors' noise, final model",
                               Format("%.2f x the floor", floor.ratio), floor.p_value,
                               r.floor_shows_structure,
                               "the residual is larger than the sensors' own noise and the "
                               "repetitions' own scatter explain"});
  }
  for (const CovariateTest& t : r.covariates.tests) {
    if (!t.tested) continue;
    page->structure.push_back({"residual against " + t.name, "F = " + Format("%.2f", t.f),
                               t.p_value, t.significant, CovariateFinding(t)});
  }
}

void AddCandidates(const DiagnoseResult& r, io::DiagnosePageData* page) {
  for (std::size_t k = 0; k < r.rounds.size(); ++k) {
    const double threshold = r.rounds[k].threshold;  // alpha / (candidates fitted)
    for (const CandidateResult& c : r.rounds[k].candidates) {
      page->candidates.push_back({static_cast<int>(k) + 1, effects::Info(c.id).name,
                                  c.separable_fraction, c.resolvable, c.fitted,
                                  c.mean_improvement, c.p_value, threshold, c.delta_bic,
                                  c.explains, c.accepted, c.verdict});
    }
  }
}

// Nominal and the written calibration on each held-out run, as `report` computes them
// (validation/trajectory_metrics.h), so that both commands print one CF for one calibration.
void AddHeldOut(const RobotModelInterface& model, const std::vector<TrackRun>& held_out,
                const DiagnoseChoice& choice, io::DiagnosePageData* page) {
  for (const TrackRun& run : held_out) {
    const TrajectoryErrors b =
        EvaluateTrajectory(model, run.aligned, run.track, model.robot().nominal, {});
    const TrajectoryErrors a =
        EvaluateTrajectory(model, run.aligned, run.track, choice.parameters, choice.effects);
    const auto start_frame = [&](const TrajectoryErrors& e) {
      const double c = std::cos(run.aligned.start.theta), s = std::sin(run.aligned.start.theta);
      const double dx = e.final_odometry.x - e.final_ground_truth.x;
      const double dy = e.final_odometry.y - e.final_ground_truth.y;
      return io::Point2{c * dx + s * dy, -s * dx + c * dy};
    };
    page->held_out.push_back({run.aligned.id, b.cf, a.cf, b.rms_distance_m, a.rms_distance_m,
                              start_frame(b), start_frame(a)});
  }
}

}  // namespace

io::DiagnosePageData MakeDiagnosePage(const DiagnosePageSource& source,
                                      const RobotModelInterface& model,
                                      const std::vector<TrackRun>& held_out,
                                      const DiagnoseResult& result,
                                      const DiagnosisCalibration& calibration,
                                      const std::string& report) {
  const DiagnoseChoice& choice = calibration.choice;
  io::DiagnosePageData page;
  const Robot& robot = model.robot();
  page.tool_version = kVersion;
  page.dataset = source.dataset;
  page.split = source.split;
  page.robot_name = robot.name;
  page.model = robot.model;
  page.selected = choice.name;
  page.text_report = report;
  page.csv_written = source.csv_written;
  SetConclusion(result, &page);
  AddStructureTests(result, &page);
  AddCandidates(result, &page);
  for (const DiagnoseChoice& c : calibration.gate)
    page.gate.push_back({c.name, c.cf_after, c.name == choice.name});
  AddHeldOut(model, held_out, choice, &page);
  page.unexplained = result.not_identifiable;
  for (const CovariateTest& t : result.covariates.tests) {
    if (t.significant) page.unexplained.push_back(CovariateFinding(t));
  }
  if (result.unexplained_structure && page.unexplained.empty()) {
    page.unexplained.push_back("structure in the residual that no candidate effect explains "
                               "(see the tests above)");
  }
  for (const std::string& line : result.record_next) page.unexplained.push_back(line);
  const bool has_sigma = static_cast<int>(choice.sigma.size()) == robot.NumParameters();
  for (int k = 0; k < robot.NumParameters(); ++k) {
    page.parameters.push_back(ReportParameterOf(robot, k, choice.parameters[k], has_sigma,
                                                has_sigma ? choice.sigma[k] : 0.0));
  }
  for (const effects::EffectValue& value : choice.effects) {
    page.effects.push_back(ReportEffectOf(value));
  }
  return page;
}

}  // namespace fitcal
