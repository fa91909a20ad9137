#pragma once
// Outputs are written whole or not at all: the text goes to a temporary file in the target's
// directory, is flushed to disk and renamed over the target, so a crash or a failed run never
// leaves a half-written file and a previous output survives until the new one is complete.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fitcal::io {

// Throws std::runtime_error (with the path) when the file cannot be written.
void WriteFileAtomically(const std::string& path, std::string_view contents);

// A set of files written together (a command's .csv, .md and trace): every one is written to its
// temporary first, and only when all are complete are they renamed over their targets, so a
// failure while writing (a full disk, a file-size limit, a bad path) leaves every previous file
// as it was. Throws std::runtime_error naming the file.
void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files);

// Where the temporaries of an output `path` go: "<dir>/.<name>.tmp-<pid>-" (+ a unique suffix):
// hidden beside the target (same file system, so the rename is atomic) and named after the writing
// process, so that a later writer can tell a stale one from a live writer's.
std::string TemporaryPrefix(const std::string& path);

// Removes the temporaries of `path` left by processes that no longer run (killed with SIGKILL,
// a power loss): files and staged directories alike. A temporary of a live process stays.
void RemoveStaleTemporaries(const std::string& path);

// Installs SIGINT/SIGTERM/SIGHUP handlers that remove the temporary file of a write in flight and
// then let the signal end the process as it would have (same exit status). Signals a parent set
// to be ignored (nohup) stay ignored. SIGKILL cannot be caught: after a kill -9 between writing
// and renaming, the previous output is intact and a hidden `.<name>.tmp-<pid>-XXXXXX` file is
// left beside it, which the next write of the same output removes (RemoveStaleTemporaries).
void RemoveTemporaryFilesOnSignals();

// The directory being staged (io/staged_directory.h), "" when none: on SIGINT/SIGTERM/SIGHUP the
// handler also removes the directory and everything in it (subdirectories included).
void SetStagingDirectoryForSignals(const std::string& dir);

// Fault-injection point for the tests: when the environment variable FITCAL_TEST_STOP_AT equals
// `stage`, the process stops itself (SIGSTOP) so a test can deliver a signal at exactly that
// point. Without the variable it does nothing.
void StopHereForTests(const char* stage);

}  // namespace fitcal::io
