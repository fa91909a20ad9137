#pragma once
// Training / validation split by trajectory label (e.g. train on circles, validate on squares):
// the companion of the repetition split (run_split.h) for data sets whose repetitions are not
// comparable across labels (OptiOdom: trajectory = path type + session, repetition = run number).
//
// A selector is either a comma-separated list of exact labels ("circular_221220201643,square_2")
// or, when it is not such a list of labels present in the data, a POSIX extended regular
// expression searched in each label ("^circular"). A run trains when its label matches. POSIX,
// not std::regex's ECMAScript: glibc matches without backtracking, where std::regex took 28 s on
// '(a+)+$' against a 30-character label and doubled with every character more.

#include <memory>
#include <string>
#include <vector>

#include <regex.h>

namespace fitcal {

class TrajectorySelector {
 public:
  // Throws std::invalid_argument for an empty text or an invalid regular expression.
  TrajectorySelector(const std::string& text, const std::vector<std::string>& labels_present);
  bool Matches(const std::string& label) const;
  const std::string& text() const { return text_; }
  bool is_list() const { return is_list_; }

 private:
  std::string text_;
  bool is_list_ = false;
  std::vector<std::string> list_;
  std::shared_ptr<regex_t> regex_;  // compiled once, when not a list
};

}  // namespace fitcal
