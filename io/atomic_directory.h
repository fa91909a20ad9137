#pragma once
// A directory of outputs written whole or not at all (a data set, a report): its files are
// written into a fresh temporary sibling `<dir>.tmp-XXXXXX`, which then takes the place of `dir`
// in one rename. A failure, or an exception from the writer, removes the temporary and leaves a
// previous `dir` as it was. Replacing an existing `dir` swaps the two atomically
// (renameat2 RENAME_EXCHANGE) and removes the old one afterwards; where the file system cannot
// exchange, the old directory is moved aside first (a moment without `dir`, never a mixed one).
// SIGKILL between writing and renaming leaves `<dir>.tmp-XXXXXX` beside an intact `dir`.

#include <functional>
#include <string>

namespace fitcal::io {

// Calls write(tmp) with the temporary directory's path, then puts it in place of `dir`. With
// replace false an existing `dir` is an error (std::runtime_error; nothing written). Throws
// std::runtime_error naming the path when a directory cannot be created or renamed.
void WriteDirectoryAtomically(const std::string& dir, bool replace,
                              const std::function<void(const std::string& tmp)>& write);

}  // namespace fitcal::io
