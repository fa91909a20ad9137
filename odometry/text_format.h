#pragma once

#include <cstdarg>
#include <string>

namespace fitcal {

// printf-style formatting into a std::string, the project's one way to format numbers into text.
// The format attribute makes -Wformat (in -Wall, an error under FITCAL_WERROR) check every call's
// arguments against its literal format: an int under "%f" or a double under "%d" no longer
// compiles. A wrapper that took doubles and forwarded its format to snprintf printed
// "no improvement on the 1488919704 held-out runs: CF 20.0000" (issue 42); the check
// `format_check` (tests/checks/format_check.cmake) refuses a new such wrapper.
std::string StrFormat(const char* format, ...) __attribute__((format(printf, 1, 2)));

// StrFormat, or "-" when `value` is not finite: a number nothing measured shows a dash, not "nan".
std::string StrFormatFinite(double value, const char* format, ...)
    __attribute__((format(printf, 2, 3)));

// A number as a message quotes it: six significant digits ("%.6g"), as an input file showed it.
std::string MessageNumber(double value);

// One number through a format chosen at run time (a table's column format): `format` must hold
// exactly one conversion of a double (%f, %e, %g, %a with flags, width and precision, no length
// modifier) besides "%%"; anything else throws std::logic_error, in release builds too, so a
// mismatched format fails every test that prints it instead of printing a wrong number. "-" when
// `value` is not finite.
std::string FormatDouble(const char* format, double value);

}  // namespace fitcal
