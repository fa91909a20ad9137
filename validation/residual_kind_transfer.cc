#include "validation/residual_kind_transfer.h"

#include <cmath>
#include <cstdio>
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

struct Judge {
  ResidualKind proposed, alternative;
  const FitByKind& fit_on;
  const ScoreOnRuns& score;

  // Both kinds fitted on `training`, judged on `judged`; false when a fit is not usable.
  bool Compare(const std::vector<AlignedRun>& training, const std::vector<AlignedRun>& judged,
               KindComparison* out) const {
    const std::optional<std::vector<double>> p = fit_on(proposed, training);
    const std::optional<std::vector<double>> a = fit_on(alternative, training);
    if (!p || !a) return false;
    out->runs = static_cast<int>(judged.size());
    out->proposed = score(*p, judged);
    out->alternative = score(*a, judged);
    return true;
  }
};

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
  const Judge judge{proposed, alternative, fit_on, score};
  const auto held_out = RunsByFamily(split.validation);
  if (const auto free = held_out.find(kFreeDriving); free != held_out.end()) {
    KindComparison c;
    c.judged_on = kFreeDriving;
    c.fitted_on = "all training runs";
    if (!judge.Compare(split.training, free->second, &c)) return j;
    j.on_free_driving = true;
    j.comparisons.push_back(std::move(c));
  } else {
    const auto training = RunsByFamily(split.training);
    if (training.size() < 2) return j;
    for (const auto& [family, runs] : training) {
      std::vector<AlignedRun> others;
      for (const AlignedRun& run : split.training)
        if (TrajectoryFamily(run.trajectory) != family) others.push_back(run);
      KindComparison c;
      c.judged_on = family;
      c.fitted_on = FamiliesExcept(training, family);
      if (!judge.Compare(others, runs, &c)) return j;
      j.comparisons.push_back(std::move(c));
    }
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
    lines.push_back(line);
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
