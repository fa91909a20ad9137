#include "fit/trajectory_split.h"

#include <algorithm>
#include <memory>
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
  auto compiled = std::make_unique<regex_t>();  // a failed regcomp frees what it made
  if (const int code = regcomp(compiled.get(), text.c_str(), REG_EXTENDED | REG_NOSUB)) {
    char why[256];
    regerror(code, compiled.get(), why, sizeof why);
    // A usage error (exit 2), as a malformed --train-reps is: the flag's text, not the data.
    throw UsageError("trajectory selector '" + text +
                     "' is neither a list of labels in the data nor a valid regular expression (" +
                     why + ")");
  }
  regex_ = std::shared_ptr<regex_t>(compiled.release(), [](regex_t* r) {
    regfree(r);
    delete r;
  });
}

bool TrajectorySelector::Matches(const std::string& label) const {
  if (is_list_) return std::find(list_.begin(), list_.end(), label) != list_.end();
  return regexec(regex_.get(), label.c_str(), 0, nullptr, 0) == 0;
}

}  // namespace fitcal
