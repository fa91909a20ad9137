#pragma once
// The parts of a robot YAML that every model shares: `bounds:` pairs, the `encoder:` ticks block
// and the `effects:` list, read strictly (unknown keys are errors) and written back in the same
// schema. Each model's reader (models/<model>/) uses these for the common keys.

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "io/yaml_reader.h"
#include "odometry/robot.h"

namespace fitcal::io {

// [lo, hi] of `key` times `scale`; InputError when lo > hi.
Interval ReadBoundsPair(YamlMap& map, const std::string& key, double scale);

// `encoder: {ticks_per_rev: N, cumulative: false|true, counter_bits: 16|32}` (counter_bits
// optional); nullopt for a null node.
std::optional<EncoderTicks> ReadEncoderTicksNode(const YAML::Node& node, const std::string& path);

// `<channel>_encoder: {ticks_per_rev: N, zero_tick: Z}` of each angle channel of `robot` that the
// robot YAML declares: the channel may then be recorded as counts in the CSV column
// `ticks_<channel>` (its ticks_column is set here; io/log_files.h converts them).
void ReadAngleEncoders(YamlMap& map, Robot* robot);

// `effects:` - a list of {name: <registry name>, <parameter>: value, ...} maps, each parameter
// named as in odometry/effects.h (units in the name) and inside its bounds; optional
// `sigma_<parameter>` keys carry the fitted uncertainty.
std::vector<effects::EffectValue> ReadEffectsNode(const YAML::Node& node, const std::string& path);

// A name that a model builds CSV columns from (a castor's, a traction wheel's): letters, digits
// and '_' only, not empty.
bool IsColumnSafe(const std::string& name);

// The nominal must lie inside the box the fit may search: InputError naming the parameter.
void CheckNominalInsideBounds(const Robot& robot, const std::string& path, int line);

// Emitters for the same blocks (inside an open top-level map).
void EmitBoundsPair(YAML::Emitter& out, const std::string& key, const Interval& v, double scale);
void EmitEncoderAndEffects(YAML::Emitter& out, const Robot& robot);
// The robot's encoder block with `effects` in place of the ones it declares.
void EmitEncoderAndEffects(YAML::Emitter& out, const Robot& robot,
                           const std::vector<effects::EffectValue>& effects);

// `key: [[row 0], [row 1], ...]` at full precision (16 digits), indented as one key of the
// calibration block it follows: the matrix a model adds for firmware that takes it (omni3's M^-1
// of Palacin Eq. 6, the omni model's forward matrix). Ends without a newline.
std::string CalibrationMatrixYaml(const std::string& key, const Eigen::MatrixXd& matrix);

}  // namespace fitcal::io
