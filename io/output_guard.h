#pragma once
// What an output may replace: the one rule of every command that writes (README, "Outputs").
//   1. Running a command again replaces its own previous output at --out: a calibration of the
//      same robot (fit, diagnose, export --calibration-out), the parameter file of
//      the same controller node (export), compare's tables, a data set fitcal wrote (import,
//      simulate), a report or page directory holding only the files the command writes. Each is
//      recreated from inputs that still exist (an output never overlaps an input), so replacing it
//      loses nothing.
//   2. Anything else at --out is refused with exit status 2 (UsageError) and nothing written.
//      --force replaces it when it is a regular file (another robot's calibration, another YAML)
//      or a directory fitcal wrote as another kind of output.
//   3. Never, --force or not: an input of the run (the data set, the robot YAML, a log, a session
//      folder), a directory holding a file fitcal did not write there, a FIFO or a device.

#include <set>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/staged_directory.h"

namespace fitcal::io {

// The help of every --force flag: one meaning for files and one for directories (the rule above).
inline constexpr char kForceFileHelp[] =
    "Replace a file at --out that is not this command's previous output, e.g. another robot's "
    "calibration (README, Outputs; refused otherwise: exit 2)";
inline constexpr char kForceDirectoryHelp[] =
    "Replace a directory fitcal wrote as another kind of output; a data set fitcal wrote is "
    "replaced without it, a directory holding other files never (README, Outputs)";

// Empty when writing `out` is fine: it does not exist, or it is a robot YAML of the same `name`.
// Otherwise the one-line reason to refuse (the caller allows it with --force).
std::string OverwriteRefusal(const std::string& out, const std::string& robot_name);

// The same for a ROS 2 parameter file: empty when `out` does not exist or is the parameter file
// of the same top-level node (`node_name: {ros__parameters: ...}`).
std::string ParameterFileOverwriteRefusal(const std::string& out, const std::string& node_name);

// The same for a text output recognised by how it starts (compare's tables): empty when `out`
// does not exist or its first line starts with `first_line` (the command's previous output).
std::string TextOutputOverwriteRefusal(const std::string& out, const std::string& first_line);

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

// Directory outputs of a kind (a data set: imports and simulators). Each such output carries the
// marker file kOutputMarker naming its kind and every file written, so a later writer recognises
// it; a data set without one (written before the marker existed) is recognised by its
// dataset.yaml listing every file there. Empty when `out` may be written: `out` does not exist,
// is an empty directory, is a recognised output of the same kind (rule 1), or (with `force`) a
// directory fitcal wrote as another kind. Refuses, `force` or not: an empty `out`, an `out` that
// is, holds or sits inside one of `inputs` or of what the process has read
// (io/input_registry.h), a file, a directory holding anything fitcal did not write there.
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

}  // namespace fitcal::io
