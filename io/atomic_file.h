#pragma once
// Outputs are written whole or not at all: the text goes to a temporary file in the target's
// directory, is flushed to disk and renamed over the target, so a crash or a failed run never
// leaves a half-written file and a previous output survives until the new one is complete.

#include <string>

namespace fitcal::io {

// Throws std::runtime_error (with the path) when the file cannot be written.
void WriteFileAtomically(const std::string& path, const std::string& contents);

}  // namespace fitcal::io
