#pragma once
// The library effects (odometry/effects.h) a command line names with --effects, read once for
// every command that takes them (fit, generalise).

#include <optional>
#include <string>
#include <vector>

#include "fit/effect_fit.h"
#include "odometry/robot.h"

namespace fitcal::tools {

// The named effects, each at zero (the value that changes nothing), or one line on stderr
// ("fitcal: <command> --effects: ...") and nullopt for an unknown name, a name given twice, or an
// effect this robot's channels cannot show (Robot::CanShow).
std::optional<EffectModel> ReadEffectList(const std::vector<std::string>& names, const Robot& robot,
                                          const std::string& command);

}  // namespace fitcal::tools
