#pragma once
// Outputs are written whole or not at all: the text goes to a temporary file in the target's
// directory, is flushed to disk and renamed over the target, so a crash or a failed run never
// leaves a half-written file and a previous output survives until the new one is complete.

#include <string>
#include <string_view>

namespace fitcal::io {

// Throws std::runtime_error (with the path) when the file cannot be written.
void WriteFileAtomically(const std::string& path, std::string_view contents);

// Installs SIGINT/SIGTERM/SIGHUP handlers that remove the temporary file of a write in flight and
// then let the signal end the process as it would have (same exit status). Signals a parent set
// to be ignored (nohup) stay ignored. SIGKILL cannot be caught: after a kill -9 between writing
// and renaming, the previous output is intact and a `<path>.tmp-XXXXXX` file is left beside it.
void RemoveTemporaryFilesOnSignals();

// The directory being staged (io/staged_directory.h), "" when none: on SIGINT/SIGTERM/SIGHUP the
// handler also removes the files WriteFileAtomically renamed into it (up to 32) and the directory.
void SetStagingDirectoryForSignals(const std::string& dir);

// Fault-injection point for the tests: when the environment variable FITCAL_TEST_STOP_AT equals
// `stage`, the process stops itself (SIGSTOP) so a test can deliver a signal at exactly that
// point. Without the variable it does nothing.
void StopHereForTests(const char* stage);

}  // namespace fitcal::io
