#pragma once
// Warnings of the loaders (input fitcal accepts after a repair, e.g. a quaternion normalised): one
// line `fitcal: warning: <file>[:line]: <what>` on stderr, or into a sink a test installs. The
// loaders run on several threads; Warn serialises the lines.

#include <functional>
#include <string>

namespace fitcal::io {

void Warn(const std::string& file, int line, const std::string& message);

// Replaces where warnings go (nullptr: stderr again); for tests.
void SetWarningSinkForTests(std::function<void(const std::string&)> sink);

}  // namespace fitcal::io
