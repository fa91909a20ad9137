#pragma once
// Checks of a calibration fitcal wrote against the truth a simulation was given.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "models/model_registry.h"

namespace fitcal::testing {

// Every parameter of the calibrated robot YAML `calibration` (nominal values, the sigmas under
// `calibration: sigma:`) within 3 of its written sigmas of `truth`'s, each printed with `label`.
inline void ExpectEveryParameterWithin3WrittenSigmas(const std::string& calibration,
                                                     const std::string& truth,
                                                     const std::string& label = "") {
  const Robot fitted = ReadRobotModelFile(calibration)->robot();
  const Robot expected = ReadRobotModelFile(truth)->robot();
  const YAML::Node sigma = YAML::LoadFile(calibration)["calibration"]["sigma"];
  ASSERT_TRUE(sigma.IsMap()) << calibration;
  ASSERT_EQ(fitted.NumParameters(), expected.NumParameters());
  for (int k = 0; k < fitted.NumParameters(); ++k) {
    const ParameterInfo& info = fitted.parameters[k];
    const double s = sigma[info.KeyName()].as<double>() / info.DisplayScale();
    const double error = fitted.nominal[k] - expected.nominal[k];
    std::printf("%s %-18s error %+.3e sigma %.3e (%.2f sigma)\n", label.c_str(), info.name.c_str(),
                error, s, error / s);
    ASSERT_GT(s, 0.0) << info.name;
    EXPECT_LT(std::abs(error), 3.0 * s) << info.name;
  }
}

}  // namespace fitcal::testing
