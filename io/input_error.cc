#include "io/input_error.h"

namespace fitcal::io {

const char* ToString(InputErrorKind kind) {
  switch (kind) {
    case InputErrorKind::kMissingFile:
      return "missing file";
    case InputErrorKind::kEmptyFile:
      return "empty file";
    case InputErrorKind::kBadHeader:
      return "bad header";
    case InputErrorKind::kWrongColumnCount:
      return "wrong column count";
    case InputErrorKind::kNonNumeric:
      return "non-numeric field";
    case InputErrorKind::kNonFinite:
      return "non-finite value";
    case InputErrorKind::kNonIncreasingTime:
      return "time not increasing";
    case InputErrorKind::kTooFewSamples:
      return "too few samples";
    case InputErrorKind::kNoOverlap:
      return "no time overlap";
    case InputErrorKind::kUnknownModel:
      return "unknown model";
    case InputErrorKind::kDuplicateRunId:
      return "duplicate run id";
    case InputErrorKind::kWrongYamlType:
      return "wrong YAML type";
    case InputErrorKind::kMissingKey:
      return "missing key";
    case InputErrorKind::kUnknownKey:
      return "unknown key";
    case InputErrorKind::kBadValue:
      return "bad value";
    case InputErrorKind::kBadPath:
      return "bad path";
    case InputErrorKind::kYamlSyntax:
      return "YAML syntax";
    case InputErrorKind::kTooLarge:
      return "file too large";
  }
  return "input error";
}

namespace {
std::string Format(const std::string& file, int line, const std::string& message) {
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line);
  return out + ": " + message;
}
}  // namespace

InputError::InputError(InputErrorKind kind, std::string file, int line, const std::string& message)
    : std::runtime_error(Format(file, line, message)),
      kind_(kind),
      file_(std::move(file)),
      line_(line) {}

}  // namespace fitcal::io
