#include "validation/verdict.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "fit/statistics.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

VerdictReason Reason(VerdictLevel level, const char* check, const char* section,
                     std::string message) {
  return {level, check, section, std::move(message)};
}

VerdictReason ConvergenceReason(const std::string& termination) {
  if (termination.find("FAIL") != std::string::npos) {
    return Reason(VerdictLevel::kFail, "convergence", "calibration",
                  "the solver failed (" + termination + ")");
  }
  // Ceres' iteration limit: the last point, not an optimum. (NLopt's global methods stop at
  // their evaluation budget by design: MAXEVAL_REACHED is their normal end.)
  if (termination.find("NO_CONVERGENCE") != std::string::npos) {
    return Reason(VerdictLevel::kWarn, "convergence", "calibration",
                  "the solver stopped at a limit (" + termination + "), not at an optimum");
  }
  return Reason(VerdictLevel::kPass, "convergence", "calibration",
                "the solver converged (" + termination + ")");
}

// "a, b and c" of at most `most` names.
std::string NameList(const std::vector<std::string>& names, std::size_t most = 6) {
  std::string out;
  for (std::size_t i = 0; i < names.size() && i < most; ++i) {
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  }
  if (names.size() > most) out += " and " + std::to_string(names.size() - most) + " more";
  return out;
}

// Worse by more than kRegressionTolerance of the nominal's value, in the mean CF or the mean final
// position error. The comparison is paired (the same runs replayed twice), so the ground truth's
// noise cancels and no noise margin is needed; the tolerance only keeps changes nobody would act
// on (0.0528 -> 0.0529 on a diff-drive session of OptiOdom) out of the verdict.
bool Regressed(const GroupOutcome& g) {
  const double k = 1.0 + kRegressionTolerance;
  return g.cf_after > k * g.cf_before || g.final_position_after_m > k * g.final_position_before_m;
}

std::string RegressionText(const GroupOutcome& g) {
  return g.name + " (CF " +
         StrFormat("%.4f -> %.4f, final position %.0f", g.cf_before, g.cf_after,
                   1e3 * g.final_position_before_m) +
         StrFormat(" -> %.0f mm)", 1e3 * g.final_position_after_m);
}

VerdictReason RegressionReason(const VerdictInputs& in) {
  std::vector<std::string> worse;
  for (const std::vector<GroupOutcome>* list : {&in.families, &in.trajectories}) {
    for (const GroupOutcome& g : *list) {
      if (Regressed(g)) worse.push_back(RegressionText(g));
    }
  }
  if (worse.empty()) {
    return Reason(VerdictLevel::kPass, "regressions", "groups",
                  "no trajectory group and no trajectory is more than 5 % worse than with the "
                  "nominal");
  }
  return Reason(
      VerdictLevel::kWarn, "regressions", "groups",
      std::to_string(worse.size()) +
          " held-out group(s) more than 5 % worse than with the nominal in mean CF or final "
          "position error: " +
          NameList(worse, 4));
}

VerdictReason NoiseFloorReason(const NoiseFloorTest& t) {
  if (!t.available) {
    return Reason(VerdictLevel::kSkip, "noise_floor", "residuals",
                  "not measured: no trajectory has two validation runs");
  }
  const std::string numbers =
      StrFormat(
          "systematic final position error %.1f mm RMS against a repetition noise of %.1f mm "
          "per axis",
          1e3 * t.systematic_rms_m, 1e3 * t.noise_sigma_m) +
      StrFormat(" (F = %.2f, p = %.2g)", t.f_statistic, t.p_value);
  // Significant and larger than one run's own noise (sqrt(2) sigma in the plane): a model that
  // lacks an effect, not a noisy data set.
  if (t.p_value < kNoiseFloorAlpha && t.systematic_rms_m > std::sqrt(2.0) * t.noise_sigma_m) {
    return Reason(VerdictLevel::kWarn, "noise_floor", "residuals",
                  "the residual is above the noise floor: " + numbers +
                      "; the model lacks an effect (try fitcal diagnose)");
  }
  // Significant but smaller than one run's noise: detectable, not worth a model change. Said
  // so, so that a PASS never stands beside a tiny p unexplained.
  if (t.p_value < kNoiseFloorAlpha) {
    return Reason(VerdictLevel::kPass, "noise_floor", "residuals",
                  "a systematic residual is detectable but smaller than one run's own noise "
                  "(sqrt(2) sigma): " +
                      numbers + "; not worth a model change");
  }
  return Reason(VerdictLevel::kPass, "noise_floor", "residuals",
                "the residual is at the noise floor (no significant systematic part): " +
                    numbers);
}

}  // namespace

const char* ToString(VerdictLevel level) {
  switch (level) {
    case VerdictLevel::kSkip:
      return "SKIP";
    case VerdictLevel::kPass:
      return "PASS";
    case VerdictLevel::kWarn:
      return "WARN";
    case VerdictLevel::kFail:
      return "FAIL";
  }
  return "?";
}

// F test of the trajectory means against the scatter within trajectories. Under "no systematic
// error" every mean m_t of n_t runs has E[n_t |m_t|^2] = 2 sigma^2, so
//   F = (sum_t n_t |m_t|^2 / 2K) / (sum_t sum_i |e_ti - m_t|^2 / 2 sum_t (n_t - 1))
// follows F(2K, 2 sum (n_t - 1)) (two axes, K trajectories).
NoiseFloorTest TestAgainstNoiseFloor(const std::vector<FinalErrorSample>& errors) {
  struct Group {
    double sx = 0.0, sy = 0.0, sxx = 0.0;
    int n = 0;
  };
  std::map<std::string, Group> groups;
  for (const FinalErrorSample& e : errors) {
    Group& g = groups[e.trajectory];
    g.sx += e.ex_m;
    g.sy += e.ey_m;
    g.sxx += e.ex_m * e.ex_m + e.ey_m * e.ey_m;
    ++g.n;
  }
  NoiseFloorTest t;
  double within = 0.0, between = 0.0;
  int dof_within = 0, runs = 0;
  for (const auto& [label, g] : groups) {
    const double mean_sq = (g.sx * g.sx + g.sy * g.sy) / (static_cast<double>(g.n) * g.n);
    between += g.n * mean_sq;
    within += std::max(0.0, g.sxx - g.n * mean_sq);
    dof_within += 2 * (g.n - 1);
    runs += g.n;
  }
  t.trajectories = static_cast<int>(groups.size());
  if (dof_within == 0 || within <= 0.0) return t;
  t.available = true;
  const double dof_between = 2.0 * t.trajectories;
  t.noise_sigma_m = std::sqrt(within / dof_within);
  t.systematic_rms_m = std::sqrt(between / runs);
  t.f_statistic = (between / dof_between) / (within / dof_within);
  t.p_value = stats::FUpperTail(t.f_statistic, dof_between, dof_within);
  return t;
}

Verdict JudgeCalibration(const VerdictInputs& in) {
  Verdict v;
  const GroupOutcome& all = in.overall;
  if (all.cf_after >= all.cf_before) {
    v.reasons.push_back(Reason(
        VerdictLevel::kFail, "improvement", "summary",
        StrFormat("no improvement on the %d held-out runs: CF %.4f with the calibration, %.4f with "
                  "the nominal",
                  all.runs, all.cf_after, all.cf_before)));
  } else {
    v.reasons.push_back(
        Reason(VerdictLevel::kPass, "improvement", "summary",
               StrFormat("held-out CF %.4f -> %.4f (%.0f %% lower)", all.cf_before, all.cf_after,
                         100.0 * (all.cf_before - all.cf_after) / all.cf_before) +
                   " on " + std::to_string(all.runs) + (all.runs == 1 ? " run" : " runs")));
  }
  v.reasons.push_back(RegressionReason(in));
  if (!in.termination.empty()) v.reasons.push_back(ConvergenceReason(in.termination));
  v.reasons.push_back(
      in.at_bound.empty()
          ? Reason(VerdictLevel::kPass, "bounds", "parameters", "no parameter rests on a bound")
          : Reason(VerdictLevel::kWarn, "bounds", "parameters",
                   NameList(in.at_bound) +
                       " rest(s) on a bound of the robot's box: the box, not the "
                       "data, decided the value"));
  if (in.has_training_cf && in.training_cf_after > 0.0) {
    const double ratio = all.cf_after / in.training_cf_after;
    const std::string numbers =
        StrFormat("held-out CF %.4f against %.4f on the training runs (%.1fx)", all.cf_after,
                  in.training_cf_after, ratio);
    v.reasons.push_back(ratio > kGapFactor
                            ? Reason(VerdictLevel::kWarn, "generalisation", "summary",
                                     numbers + ": the calibration fits its training runs much "
                                               "better than these")
                            : Reason(VerdictLevel::kPass, "generalisation", "summary", numbers));
  }
  v.reasons.push_back(NoiseFloorReason(in.noise_floor));
  if (!in.drift_measured) {
    v.reasons.push_back(Reason(VerdictLevel::kSkip, "drift", "drift",
                               StrFormat("not measured: the held-out runs are too short for its "
                                         "windows (the longest travels %.2f m of ground-truth "
                                         "path)",
                                         in.longest_path_m)));
  }
  if (in.identifiability_checked) {
    v.reasons.push_back(
        in.identifiable ? Reason(VerdictLevel::kPass, "identifiability", "identifiability",
                                 "the training runs determine every parameter")
                        : Reason(VerdictLevel::kWarn, "identifiability", "identifiability",
                                 "the training runs do not determine every parameter on its own "
                                 "(undetermined, correlated or ill-conditioned)"));
  }
  std::stable_sort(
      v.reasons.begin(), v.reasons.end(),
      [](const VerdictReason& a, const VerdictReason& b) { return a.level > b.level; });
  for (const VerdictReason& r : v.reasons) v.level = std::max(v.level, r.level);
  return v;
}

}  // namespace fitcal
