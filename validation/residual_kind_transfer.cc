#include "validation/residual_kind_transfer.h"

#include <cmath>
#include <cstdio>
#include <future>
#include <map>

#include "odometry/text_format.h"
#include "validation/trajectory_family.h"

namespace fitcal {
namespace {

constexpr const char* kFreeDriving = "free";
constexpr double kJudgedDriftLength_m = 2.0;  // the everyday window between 1 and 5 m

const DriftAtLength* DriftAt(const EverydayDrivingMetrics& m, double length_m) {
  for (const DriftAtLength& d : m.drift)
    if (std::abs(d.length_m - length_m) < 1e-9 && d.windows > 0) return &d;
  return nullptr;
}

// Counts the comparisons of one kind of run (CF, drift per 2 m where it has windows, ATE) and
// those the alternative wins (strictly lower).
void CountWins(const KindComparison& c, int* wins, int* total) {
  const auto count = [&](double proposed, double alternative) {
    ++*total;
    if (alternative < proposed) ++*wins;
  };
  count(c.proposed.cf, c.alternative.cf);
  const DriftAtLength* p = DriftAt(c.proposed, kJudgedDriftLength_m);
  const DriftAtLength* a = DriftAt(c.alternative, kJudgedDriftLength_m);
  if (p != nullptr && a != nullptr) count(p->translation_percent, a->translation_percent);
  count(c.proposed.mean_ate_rmse_m, c.alternative.mean_ate_rmse_m);
}

// One comparison to make: both kinds fitted on `training`, judged on `judged`.
struct PendingComparison {
  KindComparison comparison;
  std::vector<AlignedRun> training, judged;
  std::future<std::optional<std::vector<double>>> proposed, alternative;
};

// Every fit of every comparison at once, each on a thread of its own (the folds are independent;
// the caller's fits may start from a fit of all runs, so each ends in a few steps), then the
// scores; false when a fit is not usable.
bool FitAndScore(ResidualKind proposed, ResidualKind alternative, const FitByKind& fit_on,
                 const ScoreOnRuns& score, std::vector<PendingComparison>* pending,
                 std::vector<KindComparison>* out) {
  for (PendingComparison& c : *pending) {
    c.proposed = std::async(std::launch::async, fit_on, proposed, std::cref(c.training));
    c.alternative = std::async(std::launch::async, fit_on, alternative, std::cref(c.training));
  }
  bool usable = true;
  for (PendingComparison& c : *pending) {
    const std::optional<std::vector<double>> p = c.proposed.get();
    const std::optional<std::vector<double>> a = c.alternative.get();
    if (!p || !a) usable = false;
    if (!usable) continue;
    c.comparison.runs = static_cast<int>(c.judged.size());
    c.comparison.proposed = score(*p, c.judged);
    c.comparison.alternative = score(*a, c.judged);
    out->push_back(std::move(c.comparison));
  }
  return usable;
}

std::string FamiliesExcept(const std::map<std::string, std::vector<AlignedRun>>& by,
                           const std::string& left_out) {
  std::string names;
  for (const auto& [family, runs] : by) {
    if (family == left_out) continue;
    names += (names.empty() ? "" : "+") + family;
  }
  return names;
}

}  // namespace

ResidualKindJudgement JudgeResidualKindsByTransfer(ResidualKind proposed, ResidualKind alternative,
                                                   const RunSplit& split, const FitByKind& fit_on,
                                                   const ScoreOnRuns& score) {
  ResidualKindJudgement j;
  j.proposed = j.chosen = proposed;
  j.alternative = alternative;
  std::vector<PendingComparison> pending;
  const auto held_out = RunsByFamily(split.validation);
  if (const auto free = held_out.find(kFreeDriving); free != held_out.end()) {
    PendingComparison c;
    c.comparison.judged_on = kFreeDriving;
    c.comparison.fitted_on = "all training runs";
    c.training = split.training;
    c.judged = free->second;
    pending.push_back(std::move(c));
    j.on_free_driving = true;
  } else {
    const auto training = RunsByFamily(split.training);
    if (training.size() < 2) return j;
    for (const auto& [family, runs] : training) {
      PendingComparison c;
      for (const AlignedRun& run : split.training)
        if (TrajectoryFamily(run.trajectory) != family) c.training.push_back(run);
      c.comparison.judged_on = family;
      c.comparison.fitted_on = FamiliesExcept(training, family);
      c.judged = runs;
      pending.push_back(std::move(c));
    }
  }
  if (!FitAndScore(proposed, alternative, fit_on, score, &pending, &j.comparisons)) {
    j.comparisons.clear();
    j.on_free_driving = false;
    return j;
  }
  for (const KindComparison& c : j.comparisons) CountWins(c, &j.alternative_wins, &j.total);
  j.judged = j.total > 0;
  const bool replaces = j.on_free_driving ? 2 * j.alternative_wins > j.total
                                          : j.alternative_wins == j.total;
  if (j.judged && replaces) j.chosen = alternative;
  return j;
}

std::vector<std::string> ResidualKindJudgementLines(const ResidualKindJudgement& j) {
  std::vector<std::string> lines;
  if (!j.judged) return lines;
  char line[256];
  std::snprintf(line, sizeof(line),
                "residual kinds judged on runs of a kind they were not fitted on (%s | %s):",
                ToString(j.proposed), ToString(j.alternative));
  lines.push_back(line);
  std::snprintf(line, sizeof(line), "  %-22s %-22s %21s %21s %21s", "judged on (runs)", "fitted on",
                "CF", "drift 2 m [%]", "ATE RMSE [m]");
  lines.push_back(line);
  for (const KindComparison& c : j.comparisons) {
    const DriftAtLength* p = DriftAt(c.proposed, kJudgedDriftLength_m);
    const DriftAtLength* a = DriftAt(c.alternative, kJudgedDriftLength_m);
    char drift[64] = "-";
    if (p != nullptr && a != nullptr)
      std::snprintf(drift, sizeof(drift), "%.3f | %.3f", p->translation_percent,
                    a->translation_percent);
    const std::string judged = c.judged_on + " (" + std::to_string(c.runs) + ")";
    std::snprintf(line, sizeof(line), "  %-22s %-22s %10.4f | %-8.4f %21s %10.4f | %-8.4f",
                  judged.c_str(), c.fitted_on.c_str(), c.proposed.cf, c.alternative.cf, drift,
                  c.proposed.mean_ate_rmse_m, c.alternative.mean_ate_rmse_m);
    // The last column is left-aligned: its padding would end the line in spaces (issue 42).
    std::string row = line;
    row.erase(row.find_last_not_of(' ') + 1);
    lines.push_back(row);
  }
  // Said in full: "better on 2 of 6" alone did not tell a reader what was counted or what it takes.
  const char* rule = j.on_free_driving
                         ? "most of them (free driving is the judge that counts)"
                         : "all of them (closed loops are a weak judge of everyday driving)";
  lines.push_back(StrFormat(
      "  %s chosen: %s is better on %d of the %d comparisons above (CF, drift, ATE in each row);",
      ToString(j.chosen), ToString(j.alternative), j.alternative_wins, j.total));
  lines.push_back(StrFormat("  it replaces %s only when better on %s", ToString(j.proposed), rule));
  return lines;
}

}  // namespace fitcal
