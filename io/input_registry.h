#pragma once
// What a command has read, so that nothing it writes can destroy it. Every file opened for
// reading (io/text_file.h's OpenRegularFile, the bag readers) and every input directory a command
// names (a data set, a recording session, a bag) is recorded; every writer (io/atomic_file.h,
// io/staged_directory.h) asks OutputOverlapsInput before it creates anything. An output that is,
// holds or sits inside an input is refused whatever --force says: this is the one place that
// rule lives, so a command that forgets to check its own inputs still cannot destroy them.
//
// Off until EnableInputGuard() (fitcal's main): a test that writes, reads and rewrites a data set
// within one process is not a command with inputs.

#include <string>
#include <vector>

namespace fitcal::io {

void EnableInputGuard();

// Record an input file or directory (no effect unless the guard is enabled; thread-safe). A path
// inside a staged output of this process (BeginStagedOutput) is not recorded.
void RegisterInput(const std::string& path);

// What the process is writing is not what it read: between these two calls, files read inside
// `staging_dir` (a staged directory before its rename, io/staged_directory.h) are not inputs. A
// command may read its own output back before committing it (import rosbag2 checks the data set
// through fit's loader) and still write the rest of it (its marker) and rename it into place.
void BeginStagedOutput(const std::string& staging_dir);
void EndStagedOutput(const std::string& staging_dir);

// "" when `out` may be written; otherwise why not, without the path ("is the input file X", "holds
// the input X", "sits inside the input directory X"). Checks the recorded inputs.
std::string OutputOverlapsInput(const std::string& out);

// The same against an explicit list (a command's inputs before it has read them). An input that
// is a directory counts as a directory: an output inside it is refused.
std::string OutputOverlapsInputs(const std::string& out, const std::vector<std::string>& inputs);

// While one lives, files this thread opens are not recorded as inputs: reading an existing output
// to decide whether it may be replaced (a previous calibration's robot name, a data set's file
// list) does not make it an input.
class NotAnInput {
 public:
  NotAnInput();
  ~NotAnInput();
  NotAnInput(const NotAnInput&) = delete;
  NotAnInput& operator=(const NotAnInput&) = delete;

 private:
  bool previous_;
};

}  // namespace fitcal::io
