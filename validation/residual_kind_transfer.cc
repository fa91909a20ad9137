#include "validation/residual_kind_transfer.h"

#include <cmath>
#include <future>
#include <map>

#include "odometry/text_format.h"
#include "validation/trajectory_family.h"

namespace fitcal {
namespace {

constexpr const char* kFreeDriving = "free";

// Counts the comparisons of one kind of run (CF, drift per 2 m where it has windows, ATE) and
// those the alternative wins (strictly lower).
void CountWins(const KindComparison& c, int* wins, int* total) {
  const auto count = [&](double proposed, double alternative) {
    ++*total;
    if (alternative < proposed) ++*wins;
  };
  count(c.proposed.cf, c.alternative.cf);
  const DriftAtLength* p = DriftAt(c.proposed, kTransferDriftLength_m);
  const DriftAtLength* a = DriftAt(c.alternative, kTransferDriftLength_m);
  if (p != nullptr && a != nullptr) count(p->translation_percent, a->translation_percent);
  count(c.proposed.mean_ate_rmse_m, c.alternative.mean_ate_rmse_m);
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

const DriftAtLength* DriftAt(const EverydayDrivingMetrics& m, double length_m) {
  for (const DriftAtLength& d : m.drift)
    if (std::abs(d.length_m - length_m) < 1e-9 && d.windows > 0) return &d;
  return nullptr;
}

TransferFolds MakeTransferFolds(const RunSplit& split) {
  TransferFolds out;
  const auto held_out = RunsByFamily(split.validation);
  if (const auto free = held_out.find(kFreeDriving); free != held_out.end()) {
    out.on_free_driving = true;
    out.folds.push_back({kFreeDriving, "all training runs", split.training, free->second});
    return out;
  }
  const auto training = RunsByFamily(split.training);
  if (training.size() < 2) return out;
  for (const auto& [family, runs] : training) {
    TransferFold f;
    for (const AlignedRun& run : split.training)
      if (TrajectoryFamily(run.trajectory) != family) f.training.push_back(run);
    f.judged_on = family;
    f.fitted_on = FamiliesExcept(training, family);
    f.judged = runs;
    out.folds.push_back(std::move(f));
  }
  return out;
}

// The folds are independent and the caller's fits may start from a fit of all runs, so each ends
// in a few steps: all of them at once.
std::optional<std::vector<std::vector<EverydayDrivingMetrics>>> FitAndScoreFolds(
    const std::vector<TransferFold>& folds, int candidates, const FitCandidate& fit_on,
    const ScoreOnRuns& score) {
  std::vector<std::vector<std::future<std::optional<std::vector<double>>>>> fits(folds.size());
  for (std::size_t f = 0; f < folds.size(); ++f) {
    for (int c = 0; c < candidates; ++c) {
      fits[f].push_back(std::async(std::launch::async, fit_on, c, std::cref(folds[f].training)));
    }
  }
  std::vector<std::vector<EverydayDrivingMetrics>> scores(folds.size());
  bool usable = true;
  for (std::size_t f = 0; f < folds.size(); ++f) {
    for (auto& fit : fits[f]) {
      const std::optional<std::vector<double>> p = fit.get();  // every thread joined
      if (!p) usable = false;
      if (usable) scores[f].push_back(score(*p, folds[f].judged));
    }
  }
  if (!usable) return std::nullopt;
  return scores;
}

ResidualKindJudgement JudgeResidualKindsByTransfer(ResidualKind proposed, ResidualKind alternative,
                                                   const RunSplit& split, const FitByKind& fit_on,
                                                   const ScoreOnRuns& score) {
  ResidualKindJudgement j;
  j.proposed = j.chosen = proposed;
  j.alternative = alternative;
  const TransferFolds folds = MakeTransferFolds(split);
  if (folds.folds.empty()) return j;
  const FitCandidate fit_candidate = [&](int c, const std::vector<AlignedRun>& training) {
    return fit_on(c == 0 ? proposed : alternative, training);
  };
  const auto scores = FitAndScoreFolds(folds.folds, 2, fit_candidate, score);
  if (!scores) return j;
  j.on_free_driving = folds.on_free_driving;
  for (std::size_t f = 0; f < folds.folds.size(); ++f) {
    const TransferFold& fold = folds.folds[f];
    KindComparison c{fold.judged_on, fold.fitted_on, static_cast<int>(fold.judged.size()),
                     (*scores)[f][0], (*scores)[f][1]};
    CountWins(c, &j.alternative_wins, &j.total);
    j.comparisons.push_back(std::move(c));
  }
  j.judged = j.total > 0;
  const bool replaces = j.on_free_driving ? 2 * j.alternative_wins > j.total
                                          : j.alternative_wins == j.total;
  if (j.judged && replaces) j.chosen = alternative;
  return j;
}

std::vector<std::string> ResidualKindJudgementLines(const ResidualKindJudgement& j) {
  std::vector<std::string> lines;
  if (!j.judged) return lines;
  lines.push_back(
      StrFormat("residual kinds judged on runs of a kind they were not fitted on (%s | %s):",
                ToString(j.proposed), ToString(j.alternative)));
  lines.push_back(StrFormat("  %-22s %-22s %21s %21s %21s", "judged on (runs)", "fitted on", "CF",
                            "drift 2 m [%]", "ATE RMSE [m]"));
  for (const KindComparison& c : j.comparisons) {
    const DriftAtLength* p = DriftAt(c.proposed, kTransferDriftLength_m);
    const DriftAtLength* a = DriftAt(c.alternative, kTransferDriftLength_m);
    const std::string drift =
        p != nullptr && a != nullptr
            ? StrFormat("%.3f | %.3f", p->translation_percent, a->translation_percent)
            : "-";
    const std::string judged = c.judged_on + " (" + std::to_string(c.runs) + ")";
    // The last column is left-aligned: its padding would end the line in spaces (issue 42).
    std::string row = StrFormat("  %-22s %-22s %10.4f | %-8.4f %21s %10.4f | %-8.4f",
                                judged.c_str(), c.fitted_on.c_str(), c.proposed.cf,
                                c.alternative.cf, drift.c_str(), c.proposed.mean_ate_rmse_m,
                                c.alternative.mean_ate_rmse_m);
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
