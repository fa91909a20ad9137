#include "io/robot_yaml_blocks.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "io/input_error.h"

namespace fitcal::io {

Interval ReadBoundsPair(YamlMap& map, const std::string& key, double scale) {
  const auto [lo, hi] = map.Pair(key);
  if (lo > hi) {
    throw InputError(
        InputErrorKind::kBadValue, map.path(), map.line(map.Required(key)),
        "bounds." + key + " has lo " + std::to_string(lo) + " > hi " + std::to_string(hi));
  }
  // A box of zero width is no box the solver can search (Ceres fails on it, and the gate then
  // wrote a closed form's value outside it): fixing a parameter is --hold's job.
  if (lo == hi) {
    throw InputError(InputErrorKind::kBadValue, map.path(), map.line(map.Required(key)),
                     "bounds." + key + " has lo = hi = " + std::to_string(lo) +
                         ": a box of zero width; widen it, or fix the parameter with --hold");
  }
  return Interval{lo * scale, hi * scale};
}

bool IsColumnSafe(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

std::optional<EncoderTicks> ReadEncoderTicksNode(const YAML::Node& node, const std::string& path) {
  if (!node) return std::nullopt;
  YamlMap map(node, path, "encoder");
  EncoderTicks ticks;
  ticks.ticks_per_rev = map.Double("ticks_per_rev");
  if (!(ticks.ticks_per_rev > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, map.line(map.Required("ticks_per_rev")),
                     "encoder.ticks_per_rev must be positive");
  }
  const YAML::Node cumulative = map.Required("cumulative");
  const std::string text = YamlString(cumulative, path, "encoder.cumulative");
  if (text != "true" && text != "false") {
    throw InputError(InputErrorKind::kBadValue, path, map.line(cumulative),
                     "encoder.cumulative must be true or false, found '" + text + "'");
  }
  ticks.cumulative = text == "true";
  if (map.Has("counter_bits")) {
    ticks.counter_bits = map.Int("counter_bits");
    if (ticks.counter_bits != 16 && ticks.counter_bits != 32) {
      throw InputError(InputErrorKind::kBadValue, path, map.line(map.Required("counter_bits")),
                       "encoder.counter_bits must be 16 or 32, found " +
                           std::to_string(ticks.counter_bits));
    }
  }
  map.RejectUnread();
  return ticks;
}

void ReadAngleEncoders(YamlMap& map, Robot* robot) {
  for (ChannelInfo& channel : robot->channels) {
    const std::string key = channel.name + "_encoder";
    if (channel.kind != ChannelKind::kAngle || !map.Has(key)) continue;
    YamlMap block(map.Required(key), map.path(), key);
    const AngleEncoder e{channel.name, block.Double("ticks_per_rev"), block.Double("zero_tick")};
    if (!(e.ticks_per_rev > 0.0)) {
      throw InputError(InputErrorKind::kBadValue, map.path(),
                       block.line(block.Required("ticks_per_rev")),
                       key + ".ticks_per_rev must be positive");
    }
    block.RejectUnread();
    channel.ticks_column = "ticks_" + channel.name;
    robot->angle_encoders.push_back(e);
  }
}

std::vector<effects::EffectValue> ReadEffectsNode(const YAML::Node& node, const std::string& path) {
  std::vector<effects::EffectValue> out;
  if (!node || node.IsNull()) return out;
  ExpectYamlType(node, YAML::NodeType::Sequence, path, "robot.effects");
  for (std::size_t i = 0; i < node.size(); ++i) {
    YamlMap map(node[i], path, "effect " + std::to_string(i + 1));
    const std::string name = map.Name("name");
    effects::EffectValue e;
    try {
      e.id = effects::EffectIdFromName(name);
    } catch (const std::invalid_argument& error) {
      throw InputError(InputErrorKind::kBadValue, path, node[i].Mark().line + 1, error.what());
    }
    const effects::EffectInfo& info = effects::Info(e.id);
    for (int k = 0; k < info.num_parameters; ++k) {
      const bool optional = info.parameters_required > 0 && k >= info.parameters_required;
      if (optional && !map.Has(info.parameter_names[k])) continue;  // value 0: neutral
      e.value[k] = map.Double(info.parameter_names[k]);
      if (!(e.value[k] >= info.lower[k] && e.value[k] <= info.upper[k])) {
        throw InputError(InputErrorKind::kBadValue, path, node[i].Mark().line + 1,
                         "effect " + name + ": " + info.parameter_names[k] + " lies outside [" +
                             std::to_string(info.lower[k]) + ", " + std::to_string(info.upper[k]) +
                             "]");
      }
      const std::string sigma_key = std::string("sigma_") + info.parameter_names[k];
      if (map.Has(sigma_key)) e.sigma[k] = map.Double(sigma_key);
    }
    for (const auto& other : out) {
      if (other.id == e.id) {
        throw InputError(InputErrorKind::kBadValue, path, node[i].Mark().line + 1,
                         "effect " + name + " is listed twice");
      }
    }
    map.RejectUnread();
    out.push_back(e);
  }
  return out;
}

void CheckNominalInsideBounds(const Robot& robot, const std::string& path, int line) {
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (!robot.bounds[k].Contains(robot.nominal[k])) {
      const ParameterInfo& info = robot.parameters[k];
      const double s = info.DisplayScale();
      throw InputError(InputErrorKind::kBadValue, path, line,
                       info.name + " = " + std::to_string(robot.nominal[k] * s) + " " +
                           info.DisplayUnit() + " lies outside its bounds [" +
                           std::to_string(robot.bounds[k].lo * s) + ", " +
                           std::to_string(robot.bounds[k].hi * s) + "]");
    }
  }
}

void EmitBoundsPair(YAML::Emitter& out, const std::string& key, const Interval& v, double scale) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v.lo * scale
      << v.hi * scale << YAML::EndSeq;
}

void EmitEncoderAndEffects(YAML::Emitter& out, const Robot& robot) {
  EmitEncoderAndEffects(out, robot, robot.effects);
}

void EmitEncoderAndEffects(YAML::Emitter& out, const Robot& robot,
                           const std::vector<effects::EffectValue>& effects) {
  if (robot.encoder) {
    out << YAML::Key << "encoder" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "ticks_per_rev" << YAML::Value << robot.encoder->ticks_per_rev << YAML::Key
        << "cumulative" << YAML::Value << robot.encoder->cumulative;
    if (robot.encoder->counter_bits > 0) {
      out << YAML::Key << "counter_bits" << YAML::Value << robot.encoder->counter_bits;
    }
    out << YAML::EndMap;
  }
  for (const AngleEncoder& e : robot.angle_encoders) {
    out << YAML::Key << e.channel + "_encoder" << YAML::Value << YAML::Flow << YAML::BeginMap
        << YAML::Key << "ticks_per_rev" << YAML::Value << e.ticks_per_rev << YAML::Key
        << "zero_tick" << YAML::Value << e.zero_tick << YAML::EndMap;
  }
  if (effects.empty()) return;
  out << YAML::Key << "effects" << YAML::Value << YAML::BeginSeq;
  for (const effects::EffectValue& e : effects) {
    const effects::EffectInfo& info = effects::Info(e.id);
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << info.name;
    for (int k = 0; k < info.num_parameters; ++k) {
      out << YAML::Key << info.parameter_names[k] << YAML::Value << e.value[k];
      out << YAML::Key << std::string("sigma_") + info.parameter_names[k] << YAML::Value
          << e.sigma[k];
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

std::string CalibrationMatrixYaml(const std::string& key, const Eigen::MatrixXd& matrix) {
  YAML::Emitter out;
  out.SetDoublePrecision(16);
  out << YAML::BeginMap << YAML::Key << key << YAML::Value << YAML::BeginSeq;
  for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
    out << YAML::Flow << YAML::BeginSeq;
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) out << matrix(r, c);
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq << YAML::EndMap;
  std::string indented;
  for (char ch : "  " + std::string(out.c_str())) {
    indented += ch;
    if (ch == '\n') indented += "  ";
  }
  return indented;
}

}  // namespace fitcal::io
