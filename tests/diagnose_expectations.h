#pragma once
// What the closing-the-loop tests of each model (diff_drive_effects_test, tricycle_effects_test)
// expect of diagnose (diagnosis/diagnose.h) on a simulated robot: with one library effect
// injected, that effect alone, within four of its own sigmas (the fit's covariance, from the
// noise) of the injected size, and the held-out CF at least halved; on the clean robot, nothing.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "diagnosis/diagnose.h"
#include "fit/effect_fit.h"
#include "odometry/effects.h"

namespace fitcal::testing {

// Diagnose on two threads with the default options; the report is printed when a check fails.
inline DiagnoseResult DiagnoseOnTwoThreads(const std::vector<TrackRun>& training,
                                           const std::vector<TrackRun>& validation,
                                           const RobotModelInterface& model) {
  DiagnoseOptions options;
  options.fit.num_threads = 2;
  return Diagnose(training, validation, model, options);
}

inline void ExpectDiagnoseNamesTheInjectedEffect(const std::vector<TrackRun>& training,
                                                 const std::vector<TrackRun>& validation,
                                                 const RobotModelInterface& model,
                                                 effects::EffectId injected_id, double injected) {
  const DiagnoseResult r = DiagnoseOnTwoThreads(training, validation, model);
  SCOPED_TRACE(FormatDiagnoseReport(r, model));
  ASSERT_EQ(r.final_fit.effects.size(), 1u);
  const effects::EffectValue& e = r.final_fit.effects[0];
  EXPECT_EQ(e.id, injected_id);
  std::printf("%s %.5f +- %.5f (injected %.4f); held-out CF %.4f -> %.4f\n",
              effects::Info(e.id).name, e.value[0], e.sigma[0], injected, r.declared_validation.cf,
              r.final_validation.cf);
  EXPECT_GT(e.sigma[0], 0.0);
  EXPECT_LT(std::abs(e.value[0] - injected), 4.0 * e.sigma[0]);
  EXPECT_LT(r.final_validation.cf, 0.5 * r.declared_validation.cf);
}

inline void ExpectDiagnoseAcceptsNothing(const std::vector<TrackRun>& training,
                                         const std::vector<TrackRun>& validation,
                                         const RobotModelInterface& model) {
  const DiagnoseResult r = DiagnoseOnTwoThreads(training, validation, model);
  SCOPED_TRACE(FormatDiagnoseReport(r, model));
  EXPECT_TRUE(r.final_fit.effects.empty());
}

}  // namespace fitcal::testing
