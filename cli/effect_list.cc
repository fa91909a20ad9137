#include "cli/effect_list.h"

#include <iostream>
#include <set>
#include <stdexcept>

namespace fitcal::tools {

std::optional<EffectModel> ReadEffectList(const std::vector<std::string>& names, const Robot& robot,
                                          const std::string& command) {
  const std::string prefix = "fitcal: " + command + " --effects: ";
  EffectModel out;
  std::set<std::string> seen;
  for (const std::string& name : names) {
    effects::EffectValue e;
    try {
      e.id = effects::EffectIdFromName(name);
    } catch (const std::invalid_argument& error) {
      std::cerr << prefix << error.what() << "\n";
      return std::nullopt;
    }
    if (!seen.insert(name).second) {
      std::cerr << prefix << name << " is named twice\n";
      return std::nullopt;
    }
    if (!robot.CanShow(e.id)) {
      std::cerr << prefix << name << " needs "
                << (effects::NeedsWheelPair(e.id) ? "a robot with two wheel channels and no other"
                                                  : "an angle channel (steering)")
                << "; model " << robot.model << " cannot show it\n";
      return std::nullopt;
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace fitcal::tools
