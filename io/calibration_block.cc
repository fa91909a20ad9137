#include "io/calibration_block.h"

#include <yaml-cpp/yaml.h>

#include "io/yaml_text.h"

namespace fitcal::io {

namespace {

void EmitCalibrationOrigin(YAML::Emitter& out, const CalibrationSource& c) {
  out << YAML::Key << "method" << YAML::Value << c.method;
  out << YAML::Key << "objective" << YAML::Value << c.objective;
  out << YAML::Key << "dataset" << YAML::Value << YamlText(c.dataset);
  out << YAML::Key << "tool_version" << YAML::Value << c.tool_version;
  out << YAML::Key << "termination" << YAML::Value << c.termination;
}

void EmitCalibrationRunCounts(YAML::Emitter& out, const CalibrationSource& c) {
  out << YAML::Key << "training_repetitions" << YAML::Value << YAML::Flow << c.training_repetitions;
  out << YAML::Key << "validation_repetitions" << YAML::Value << YAML::Flow
      << c.validation_repetitions;
  out << YAML::Key << "training_runs" << YAML::Value << c.training_runs;
  out << YAML::Key << "validation_runs" << YAML::Value << c.validation_runs;
  if (!c.training_trajectories.empty()) {
    out << YAML::Key << "training_trajectories" << YAML::Value << c.training_trajectories;
  }
}

void EmitCalibrationCf(YAML::Emitter& out, const CalibrationSource& c) {
  const auto before_after = [&](const char* key, double before, double after) {
    out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "before"
        << YAML::Value << before << YAML::Key << "after" << YAML::Value << after << YAML::EndMap;
  };
  before_after("cf_training", c.cf_training_before, c.cf_training_after);
  // With every run trained there is nothing it was validated on: no figures, not zeros.
  if (c.validation_runs > 0) {
    before_after("cf_validation", c.cf_validation_before, c.cf_validation_after);
  }
}

void EmitRuns(YAML::Emitter& out, const CalibrationBlock& c) {
  EmitCalibrationRunCounts(out, c);
  if (!c.training_run_ids.empty()) {
    out << YAML::Key << "training_run_ids" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const std::string& id : c.training_run_ids) out << YamlText(id);
    out << YAML::EndSeq;
  }
  if (!c.training_fingerprint.empty()) {
    out << YAML::Key << "training_fingerprint" << YAML::Value << YAML::DoubleQuoted
        << c.training_fingerprint;
  }
  EmitCalibrationCf(out, c);
}

void EmitUncertainty(YAML::Emitter& out, const CalibrationBlock& c, const Robot& robot) {
  if (!c.has_uncertainty) {
    out << YAML::Key << "sigma" << YAML::Value << YAML::Null;
    return;
  }
  out << YAML::Key << "sigma" << YAML::Value << YAML::BeginMap;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    out << YAML::Key << info.KeyName() << YAML::Value
        << c.sigma[k] * info.DisplayScale();
  }
  out << YAML::EndMap;
  out << YAML::Key << "correlation" << YAML::Value << YAML::BeginSeq;
  out.SetDoublePrecision(4);
  for (int r = 0; r < robot.NumParameters(); ++r) {
    out << YAML::Flow << YAML::BeginSeq;
    for (int k = 0; k < robot.NumParameters(); ++k) out << c.correlation(r, k);
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq;
  out.SetDoublePrecision(10);
}

// clock_offsets: {grouping, meaning, groups: [{group, offset_s, sigma_s}]}
void EmitClockOffsets(YAML::Emitter& out, const CalibrationBlock& c) {
  if (c.clock_offsets.empty()) return;
  out << YAML::Key << "clock_offsets" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "grouping" << YAML::Value << c.clock_offset_grouping;
  out << YAML::Key << "meaning" << YAML::Value
      << "ground truth stamped t + offset_s belongs to encoder time t: subtract offset_s from "
         "the ground truth's stamps of the group's runs to align them";
  out << YAML::Key << "groups" << YAML::Value << YAML::BeginSeq;
  out.SetDoublePrecision(6);
  for (const ClockOffsetRecord& r : c.clock_offsets) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "group" << YAML::Value << YamlText(r.group)
        << YAML::Key << "offset_s" << YAML::Value << r.offset_s << YAML::Key << "sigma_s"
        << YAML::Value << r.sigma_s << YAML::EndMap;
  }
  out.SetDoublePrecision(10);
  out << YAML::EndSeq << YAML::EndMap;
}

}  // namespace

std::string CalibrationBlockYaml(const CalibrationBlock& c, const Robot& robot) {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap << YAML::Key << "calibration" << YAML::Value << YAML::BeginMap;
  EmitCalibrationOrigin(out, c);
  if (!c.selected.empty()) {
    out << YAML::Key << "selected" << YAML::Value << c.selected;
    out << YAML::Key << "selected_on" << YAML::Value << c.selected_on;
  }
  EmitRuns(out, c);
  out << YAML::Key << "held" << YAML::Value << YAML::Flow << c.held;
  if (!c.tied.empty()) out << YAML::Key << "tied" << YAML::Value << YAML::Flow << c.tied;
  out << YAML::Key << "at_bound" << YAML::Value << YAML::Flow << c.at_bound;
  if (!c.not_determined.empty()) {
    out << YAML::Key << "not_determined" << YAML::Value << YAML::Flow << c.not_determined;
  }
  EmitUncertainty(out, c, robot);
  EmitClockOffsets(out, c);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace fitcal::io
