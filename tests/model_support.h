#pragma once
// What the model tests share: labelled runs, the registry's example robots, and the final-pose cost's autodiff
// Jacobian against central differences of the double replay (the check the harness makes for
// every registered model, tests/model_harness_test.cc, and each model's own tests on their
// robots and runs).

#include <ceres/cost_function.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "models/model_registry.h"
#include "models/pose_errors.h"
#include "odometry/aligned_run.h"

namespace fitcal::testing {

// A run with only its labels, for the tests of splits and groupings: id "<trajectory>-<repetition>".
inline AlignedRun LabelledRun(const std::string& trajectory, int repetition) {
  AlignedRun run;
  run.trajectory = trajectory;
  run.repetition = repetition;
  run.id = trajectory + "-" + std::to_string(repetition);
  return run;
}

// Every run weighed 1 m : 1 rad (the weights AnalyseDeterminedDirections takes, one per run).
inline std::vector<ResidualWeights> Unweighted(const std::vector<AlignedRun>& runs) {
  return std::vector<ResidualWeights>(runs.size());
}

// The registry's example robot of model `name` (models/model_registry.h).
inline RobotModelPtr ExampleModel(const std::string& name) {
  return ReadRobotModel(YAML::Load(FindModel(name)->example_yaml), name + " example");
}

// Expects d r / d p_k of model.FinalPoseCost(run) at p to equal (r(p + h e_k) - r(p - h e_k)) / 2h
// within 1e-6 (1 + |numeric|), r the FinalPoseError of the replay (unit weights). h = 1e-6 of
// the parameter's scale: truncation O(h^2) and rounding O(eps / h) both stay below 1e-8 of a
// derivative of order one. A `fixed_step` > 0 is h for every parameter instead.
inline void ExpectFinalPoseJacobianMatchesCentralDifferences(const RobotModelInterface& model,
                                                             const AlignedRun& run,
                                                             const std::vector<double>& p,
                                                             double fixed_step = 0.0) {
  const Robot& robot = model.robot();
  const int n = robot.NumParameters();
  std::unique_ptr<ceres::CostFunction> cost(model.FinalPoseCost(run, ResidualWeights{}));
  double r[3];
  std::vector<double> jacobian(3 * n);
  const double* parameters[] = {p.data()};
  double* jacobians[] = {jacobian.data()};
  ASSERT_TRUE(cost->Evaluate(parameters, r, jacobians));
  for (int k = 0; k < n; ++k) {
    const double h = fixed_step > 0.0 ? fixed_step : 1e-6 * robot.parameters[k].RelativeScale(p[k]);
    std::vector<double> plus = p, minus = p;
    plus[k] += h;
    minus[k] -= h;
    double r_plus[3], r_minus[3];
    FinalPoseError(model.ReplayFinalPose(plus.data(), run.samples, run.start),
                   run.final_ground_truth, ResidualWeights{}, r_plus);
    FinalPoseError(model.ReplayFinalPose(minus.data(), run.samples, run.start),
                   run.final_ground_truth, ResidualWeights{}, r_minus);
    for (int i = 0; i < 3; ++i) {
      const double numeric = (r_plus[i] - r_minus[i]) / (2.0 * h);
      EXPECT_NEAR(jacobian[i * n + k], numeric, 1e-6 * (1.0 + std::abs(numeric)))
          << run.id << " d r" << i << " / d " << robot.parameters[k].name;
    }
  }
}

}  // namespace fitcal::testing
