#include "fit/trajectory_split.h"

#include <algorithm>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "io/command_failure.h"

namespace fitcal {

TrajectorySelector::TrajectorySelector(const std::string& text,
                                       const std::vector<std::string>& labels_present)
    : text_(text) {
  if (text.empty()) throw std::invalid_argument("empty trajectory selector");
  std::vector<std::string> items;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) items.push_back(item);
  is_list_ = !items.empty() && std::all_of(items.begin(), items.end(), [&](const std::string& s) {
    return std::find(labels_present.begin(), labels_present.end(), s) != labels_present.end();
  });
  if (is_list_) {
    list_ = items;
    return;
  }
  try {
    const std::regex check(text, std::regex::ECMAScript);
    (void)check;
  } catch (const std::regex_error& e) {
    // A usage error (exit 2), as a malformed --train-reps is: the flag's text, not the data.
    throw UsageError("trajectory selector '" + text +
                                "' is neither a list of labels in the data nor a valid regular "
                                "expression (" +
                                e.what() + ")");
  }
}

bool TrajectorySelector::Matches(const std::string& label) const {
  if (is_list_) return std::find(list_.begin(), list_.end(), label) != list_.end();
  return std::regex_search(label, std::regex(text_, std::regex::ECMAScript));
}

}  // namespace fitcal
