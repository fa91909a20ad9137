#pragma once
// The one error type for bad input: which file, which line (0 = the file as a whole), what kind of
// problem and a sentence for the user. Loaders throw it; the tool's edge prints What() as one line.

#include <stdexcept>
#include <string>

namespace fitcal::io {

enum class InputErrorKind {
  kMissingFile,        // cannot open / read
  kEmptyFile,          // nothing but (optional) header
  kBadHeader,          // header row is not the expected one
  kWrongColumnCount,   // a row with too few or too many fields
  kNonNumeric,         // a field that is not a number
  kNonFinite,          // NaN, Inf or out of double range
  kNonIncreasingTime,  // t not strictly increasing
  kTooFewSamples,      // fewer than two samples
  kNoOverlap,          // ground truth and encoders do not share time
  kUnknownModel,       // robot model fitcal does not know
  kDuplicateRunId,     // two runs with one id
  kWrongYamlType,      // a YAML node of the wrong kind (map / list / scalar)
  kMissingKey,         // a required YAML key is absent
  kUnknownKey,         // a YAML key nobody reads
  kBadValue,           // a value out of its allowed range (bounds lo > hi, radius <= 0, ...)
  kBadPath,            // a path that escapes the data set directory
  kYamlSyntax,         // YAML that does not parse
  kTooLarge,           // a file larger than fitcal will hold in memory
};

const char* ToString(InputErrorKind kind);

class InputError : public std::runtime_error {
 public:
  InputError(InputErrorKind kind, std::string file, int line, const std::string& message);

  InputErrorKind kind() const { return kind_; }
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  InputErrorKind kind_;
  std::string file_;
  int line_;
};

}  // namespace fitcal::io
