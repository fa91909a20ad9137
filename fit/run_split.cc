#include "fit/run_split.h"

#include <set>
#include <stdexcept>

namespace fitcal {

namespace {
int ParseInt(const std::string& s, const std::string& whole) {
  if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos) {
    throw std::invalid_argument("repetition list '" + whole + "': '" + s +
                                "' is not a whole number");
  }
  if (s.size() > 6) {  // a range of them is expanded: a million at most
    throw std::invalid_argument("repetition list '" + whole + "': " + s +
                                " is beyond the last repetition a list may name, 999999");
  }
  return std::stoi(s);
}
}  // namespace

// Calls item(text of one comma-separated item, its repetitions) for each item of `text`.
template <typename Item>
void ForEachRepetitionItem(const std::string& text, Item&& item) {
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t end = text.find(',', pos);
    if (end == std::string::npos) end = text.size();
    const std::string part = text.substr(pos, end - pos);
    const std::size_t dash = part.find('-');
    if (dash == std::string::npos) {
      item(part, std::vector<int>{ParseInt(part, text)});
    } else {
      const int lo = ParseInt(part.substr(0, dash), text);
      const int hi = ParseInt(part.substr(dash + 1), text);
      if (lo > hi)
        throw std::invalid_argument("repetition list '" + text + "': range " + part +
                                    " is reversed");
      std::vector<int> range;
      for (int r = lo; r <= hi; ++r) range.push_back(r);
      item(part, range);
    }
    pos = end + 1;
  }
}

std::vector<int> ParseRepetitionList(const std::string& text) {
  std::set<int> out;
  ForEachRepetitionItem(text, [&](const std::string&, const std::vector<int>& reps) {
    out.insert(reps.begin(), reps.end());
  });
  return {out.begin(), out.end()};
}

std::vector<int> RepetitionsNamedAlone(const std::string& text) {
  std::set<int> out;
  ForEachRepetitionItem(text, [&](const std::string& part, const std::vector<int>& reps) {
    if (part.find('-') == std::string::npos) out.insert(reps.front());
  });
  return {out.begin(), out.end()};
}

std::string FormatRepetitionList(const std::vector<int>& reps) {
  std::string out;
  for (std::size_t i = 0; i < reps.size();) {
    std::size_t j = i;
    while (j + 1 < reps.size() && reps[j + 1] == reps[j] + 1) ++j;
    if (!out.empty()) out += ",";
    out += std::to_string(reps[i]);
    if (j > i) out += "-" + std::to_string(reps[j]);
    i = j + 1;
  }
  return out.empty() ? "none" : out;
}

std::vector<int> ResolveRepetitionList(const std::string& text, const std::set<int>& present) {
  if (text != "auto") return ParseRepetitionList(text);
  const std::vector<int> all(present.begin(), present.end());
  return std::vector<int>(all.begin(), all.begin() + static_cast<long>((all.size() + 1) / 2));
}

}  // namespace fitcal
