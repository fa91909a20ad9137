#include "validation/calibration_match.h"

#include <algorithm>
#include <vector>

namespace fitcal {

namespace {

template <typename Item>
std::vector<std::string> NamesOf(const std::vector<Item>& items) {
  std::vector<std::string> names;
  for (const Item& item : items) names.push_back(item.name);
  return names;
}

std::string Listed(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return out;
}

// The same names in another order: "" when in order or not the same names.
std::string OrderRefusal(const char* what, const std::vector<std::string>& calibrated,
                         const std::vector<std::string>& dataset) {
  if (calibrated == dataset || !std::is_permutation(calibrated.begin(), calibrated.end(),
                                                    dataset.begin(), dataset.end())) {
    return "";
  }
  return "lists its " + std::string(what) + " as " + Listed(calibrated) +
         ", the data set's robot YAML as " + Listed(dataset) +
         "; values are applied by position: list them in the data set's order";
}

}  // namespace

std::string ChannelOrderRefusal(const Robot& calibrated, const Robot& dataset) {
  const std::string channels =
      OrderRefusal("channels", NamesOf(calibrated.channels), NamesOf(dataset.channels));
  if (!channels.empty()) return channels;
  return OrderRefusal("parameters", NamesOf(calibrated.parameters), NamesOf(dataset.parameters));
}

}  // namespace fitcal
