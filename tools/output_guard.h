#pragma once
// What an output may replace. `--out` must not silently replace another robot's calibration, an
// input of the same run (the data set, the robot YAML, a log), a directory of someone else's
// files, or something that is not a file at all. Shared by every command that writes.

#include <set>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/staged_directory.h"

namespace fitcal::tools {

// Empty when writing `out` is fine: it does not exist, or it is a robot YAML of the same `name`.
// Otherwise the one-line reason to refuse (the caller allows it with --force).
std::string OverwriteRefusal(const std::string& out, const std::string& robot_name);

// Empty when `out` may be written as a file. Refuses (not even --force: a usage error) a path that
// exists and is not a regular file (a directory; a FIFO or a device: renaming over /dev/null as
// root would replace the device) and a path that is one of `inputs` (the same file through any
// name or link), which writing would destroy before anyone noticed.
std::string OutputFileRefusal(const std::string& out, const std::vector<std::string>& inputs);

// Empty when `out` may be written as a directory that replaces what is there: it does not exist,
// or it is a directory holding only names in `own_names` (a previous output of the same command).
// Refuses a directory that holds anything else (the data set directory itself, a parent of it, a
// user's files), a path that is not a directory, and a directory that is one of `inputs` or holds
// one.
std::string OutputDirectoryRefusal(const std::string& out, const std::vector<std::string>& inputs,
                                   const std::set<std::string>& own_names);

// Renames a complete staged directory over `out`, after checking once more what it replaces
// (another writer may have put files there meanwhile); throws std::runtime_error otherwise.
void CommitOutputDirectory(io::StagedDirectory& staged, const std::string& out,
                           const std::vector<std::string>& inputs,
                           const std::set<std::string>& own_names);

// Directory outputs that only `--force` replaces (a data set: imports and simulators). Each such
// output carries the marker file kOutputMarker naming its kind and every file written, so a later
// writer recognises it as its own; a data set without one (written before the marker existed) is
// recognised by its dataset.yaml listing every file there. Empty when `out` may be written:
// `out` does not exist, is an empty directory, or (with `force`) is a recognised output of the
// same kind. Refuses, `force` or not: an empty `out`, an `out` that is, holds or sits inside one
// of `inputs` or of what the process has read (io/input_registry.h), a file, a directory holding
// anything fitcal did not write there.
inline constexpr char kOutputMarker[] = ".fitcal-output";
inline constexpr char kDatasetKind[] = "data set";
std::string DirectoryOutputRefusal(const std::string& out, const std::string& kind, bool force,
                                   const std::vector<std::string>& inputs);

// Writes the marker into the complete staged directory, checks DirectoryOutputRefusal once more
// (another writer may have been there meanwhile) and renames the staged directory over `out`;
// throws std::runtime_error otherwise (the staged directory is then removed by its destructor).
void CommitDirectoryOutput(io::StagedDirectory& staged, const std::string& out,
                           const std::string& kind, bool force,
                           const std::vector<std::string>& inputs);

// Every file a data set run reads: dataset.yaml, the robot YAML, each run's logs.
std::vector<std::string> DatasetInputs(const io::DatasetIndex& index);

}  // namespace fitcal::tools
