#include "validation/never_worse.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "fit/statistics.h"
#include "odometry/text_format.h"
#include "validation/trajectory_family.h"

namespace fitcal {

namespace {

double WeightedMean(const std::vector<double>& weights, const std::vector<double>& values) {
  double sum_w = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    sum_w += weights[i];
    sum += weights[i] * values[i];
  }
  return sum_w > 0.0 ? sum / sum_w : 0.0;
}

// (sum w)^2 / sum w^2: the number of equally weighted runs with the same standard error.
double EffectiveRuns(const std::vector<double>& weights) {
  double sum_w = 0.0, sum_w2 = 0.0;
  for (double w : weights) {
    sum_w += w;
    sum_w2 += w * w;
  }
  return sum_w2 > 0.0 ? sum_w * sum_w / sum_w2 : 0.0;
}

// The runs of one set: their labels, weights and both calibrations' values.
struct RunSet {
  std::string name;
  std::vector<std::size_t> index;  // into the held-out runs
};

std::vector<RunSet> RunSets(const std::vector<AlignedRun>& runs) {
  std::vector<RunSet> sets(1);
  sets[0].name = "held-out runs (" + std::to_string(runs.size()) + ")";
  std::map<std::string, std::vector<std::size_t>> by_family;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    sets[0].index.push_back(i);
    by_family[TrajectoryFamily(runs[i].trajectory)].push_back(i);
  }
  if (by_family.size() == 1) {  // the family is the whole: named, so a line says which kind
    sets[0].name = "held-out runs (" + std::to_string(runs.size()) + ", all '" +
                   by_family.begin()->first + "')";
  }
  if (by_family.size() < 2) return sets;
  for (auto& [family, index] : by_family) {
    sets.push_back({"held-out '" + family + "' runs (" + std::to_string(index.size()) + ")",
                    std::move(index)});
  }
  return sets;
}

template <typename T>
std::vector<T> Pick(const std::vector<T>& v, const std::vector<std::size_t>& index) {
  std::vector<T> out;
  for (std::size_t i : index) out.push_back(v[i]);
  return out;
}

// One measure of both calibrations on every held-out run.
struct Measure {
  std::string name;
  std::vector<double> weights, nominal, calibrated;
  bool refuses_on_all = true;     // worse on all held-out runs refuses, else warns
  bool refuses_per_family = true;  // worse on one family refuses, else warns
};

std::vector<Measure> Measures(const EverydayDrivingMetrics& nominal,
                              const EverydayDrivingMetrics& calibrated) {
  const std::vector<double> ones(nominal.per_run_cf.size(), 1.0);
  std::vector<Measure> out = {{"CF", ones, nominal.per_run_cf, calibrated.per_run_cf}};
  if (nominal.per_run_ate_m.size() != ones.size()) return out;
  out.push_back({"ATE RMSE [m]", ones, nominal.per_run_ate_m, calibrated.per_run_ate_m});
  for (std::size_t k = 0; k < nominal.drift.size() && k < calibrated.drift.size(); ++k) {
    const DriftAtLength& a = nominal.drift[k];
    if (a.windows == 0 || a.per_run_windows.size() != ones.size()) continue;
    // Drift per family and over 0.5 m warns only (docs/never_worse.md): on the real diff drive
    // the default track fit, better on all held-out runs at 1-5 m, drifts more on the squares at
    // 1 m (0.52 -> 0.89 %) and on all runs at 0.5 m (0.71 -> 0.86 %), windows the ground truth's
    // own noise (2-3 mm) and the encoder-to-ground-truth clock offset dominate.
    const bool short_window = a.length_m < 1.0;
    out.push_back({StrFormat("drift %g m [%%]", a.length_m),
                   std::vector<double>(a.per_run_windows.begin(), a.per_run_windows.end()),
                   a.per_run_translation_percent, calibrated.drift[k].per_run_translation_percent,
                   !short_window, false});
  }
  return out;
}

// Pooled over the labels that repeat, over both value lists (runs in the order of `labels`,
// weights as above; a run of weight 0 is skipped).
RepetitionSpread SpreadBetweenRepetitions(const std::vector<std::string>& labels,
                                          const std::vector<double>& weights,
                                          const std::vector<std::vector<double>>& values) {
  std::map<std::string, std::vector<std::size_t>> by_label;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (weights[i] > 0.0) by_label[labels[i]].push_back(i);
  }
  double sum_sq = 0.0;
  RepetitionSpread s;
  for (const std::vector<double>& v : values) {
    for (const auto& [label, index] : by_label) {
      if (index.size() < 2) continue;
      double mean = 0.0;
      for (std::size_t i : index) mean += v[i];
      mean /= static_cast<double>(index.size());
      if (!(mean > 0.0)) continue;  // a perfect replay scatters by nothing we could scale
      for (std::size_t i : index) sum_sq += (v[i] / mean - 1.0) * (v[i] / mean - 1.0);
      s.dof += static_cast<int>(index.size()) - 1;
    }
  }
  if (s.dof > 0) s.relative_sd = std::sqrt(sum_sq / s.dof);
  return s;
}

}  // namespace

NeverWorseJudgement JudgeMeasure(const std::string& measure, const std::string& runs,
                                 const std::vector<std::string>& labels,
                                 const std::vector<double>& weights,
                                 const std::vector<double>& nominal,
                                 const std::vector<double>& calibrated,
                                 const RepetitionSpread& fallback, int k) {
  NeverWorseJudgement j;
  j.measure = measure;
  j.runs = runs;
  j.nominal = WeightedMean(weights, nominal);
  j.calibrated = WeightedMean(weights, calibrated);
  j.spread = SpreadBetweenRepetitions(labels, weights, {nominal, calibrated});
  if (j.spread.dof == 0) j.spread = fallback;
  const double n_eff = EffectiveRuns(weights);
  if (j.spread.dof == 0 || !(n_eff > 0.0)) return j;  // not measured: margin 0
  j.t = stats::StudentTUpperQuantile(kNeverWorseAlpha / std::max(1, k), j.spread.dof);
  j.margin = j.t * j.spread.relative_sd * 0.5 * (j.nominal + j.calibrated) * std::sqrt(2.0 / n_eff);
  return j;
}

std::string NeverWorseJudgement::Description() const {
  if (spread.dof == 0) {
    return StrFormat(
        "%s %.6g -> %.6g (margin 0: no trajectory repeats, the noise is not measured)",
        measure.c_str(), nominal, calibrated);
  }
  return StrFormat(
      "%s %.6g -> %.6g, %s the margin %.3g (t %.2f x spread %.3g %% of a run's value between "
      "repetitions, %d dof)",
      measure.c_str(), nominal, calibrated, Worse() ? "more than" : "within", margin, t,
      100.0 * spread.relative_sd, spread.dof);
}

std::vector<NeverWorseJudgement> JudgeNeverWorse(const std::vector<AlignedRun>& runs,
                                                 const EverydayDrivingMetrics& nominal,
                                                 const EverydayDrivingMetrics& calibrated) {
  const std::vector<Measure> measures = Measures(nominal, calibrated);
  std::vector<std::string> labels, families;
  for (const AlignedRun& run : runs) {
    labels.push_back(run.trajectory);
    families.push_back(TrajectoryFamily(run.trajectory));
  }
  const std::vector<RunSet> sets = RunSets(runs);
  const int k = static_cast<int>(sets.size() * measures.size());
  std::vector<NeverWorseJudgement> out;
  for (const Measure& m : measures) {
    RepetitionSpread all = SpreadBetweenRepetitions(labels, m.weights, {m.nominal, m.calibrated});
    // No trajectory repeats: the runs of a family (the flower's G1-G12) stand in for repetitions;
    // their scatter holds the paths' differences too, so the margin is wider, never narrower.
    if (all.dof == 0)
      all = SpreadBetweenRepetitions(families, m.weights, {m.nominal, m.calibrated});
    for (const RunSet& set : sets) {
      out.push_back(JudgeMeasure(m.name, set.name, Pick(labels, set.index),
                                 Pick(m.weights, set.index), Pick(m.nominal, set.index),
                                 Pick(m.calibrated, set.index), all, k));
      out.back().all_runs = &set == &sets.front();
      out.back().refuses = out.back().all_runs ? m.refuses_on_all : m.refuses_per_family;
    }
  }
  return out;
}

EverydayDrivingComparison CompareEverydayDriving(const RobotModelInterface& model,
                                                 const CalibrationCandidate& nominal,
                                                 const CalibrationCandidate& calibrated,
                                                 const std::vector<AlignedRun>& runs,
                                                 const std::vector<const GroundTruthTrack*>& tracks,
                                                 int num_threads) {
  const std::vector<double> lengths = EverydayDriftLengths();
  EverydayDrivingTruths truths;  // the runs' ground-truth side, once for both
  const EverydayDrivingMetrics before = EvaluateEverydayDriving(
      model, nominal.parameters, nominal.effects, runs, tracks, lengths, num_threads, &truths);
  const EverydayDrivingMetrics after =
      EvaluateEverydayDriving(model, calibrated.parameters, calibrated.effects, runs, tracks,
                              lengths, num_threads, &truths);
  EverydayDrivingComparison c;
  c.judgements = JudgeNeverWorse(runs, before, after);
  // A row that rose says whether the runs' scatter explains it (issue 42: +13 % went unmarked).
  c.rows = EverydayDrivingRows(before, after, NeverWorseRowNotes(c.judgements));
  return c;
}

std::vector<std::string> NeverWorseRefusals(const std::string& name,
                                            const std::vector<NeverWorseJudgement>& judgements,
                                            bool refusing) {
  std::vector<std::string> out;
  for (const NeverWorseJudgement& j : judgements) {
    if (j.Worse() && j.refuses == refusing) {
      out.push_back("'" + name + "' is worse than the nominal on the " + j.runs + ": " +
                    j.Description());
    }
  }
  return out;
}

std::vector<std::string> NeverWorseWithinScatter(
    const std::string& name, const std::vector<NeverWorseJudgement>& judgements) {
  std::vector<std::string> out;
  for (const NeverWorseJudgement& j : judgements) {
    if (!j.WorseWithinScatter()) continue;
    std::string text = j.Description();
    const double change_percent = 100.0 * (j.calibrated / j.nominal - 1.0);
    text.insert(text.find(','), StrFormat(" (%+.1f %%)", change_percent));
    out.push_back("'" + name + "' is worse than the nominal on the " + j.runs +
                  ", within the runs' scatter: " + text);
  }
  return out;
}

NeverWorseSaid SayNeverWorse(const std::string& name,
                             const std::vector<NeverWorseJudgement>& judgements) {
  NeverWorseSaid said;
  said.warnings = NeverWorseRefusals(name, judgements, /*refusing=*/false);
  for (std::string& line : NeverWorseWithinScatter(name, judgements)) {
    said.warnings.push_back(std::move(line));
  }
  said.refusals = NeverWorseRefusals(name, judgements);
  return said;
}

std::map<std::string, std::string> NeverWorseRowNotes(
    const std::vector<NeverWorseJudgement>& judgements) {
  std::map<std::string, std::string> notes;
  for (const NeverWorseJudgement& j : judgements) {
    if (!j.all_runs || !(j.calibrated > j.nominal)) continue;
    notes[j.measure] =
        StrFormat("worse%s: margin %.3g",
                  j.Worse() ? " beyond the scatter" : ", within the scatter", j.margin);
  }
  return notes;
}

}  // namespace fitcal
