#include "io/output_guard.h"

#include <sys/stat.h>

#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/input_error.h"
#include "io/input_registry.h"
#include "io/yaml_reader.h"

namespace fitcal::io {

namespace fs = std::filesystem;

namespace {

std::string Refusal(const std::string& out, const std::string& why) {
  return io::OneLine(out, 200) + ": " + why;
}

// The refusal when `out` is, holds or sits inside one of `inputs` or of what was read.
std::string InputOverlap(const std::string& out, const std::vector<std::string>& inputs) {
  std::string why = io::OutputOverlapsInputs(out, inputs);
  if (why.empty()) why = io::OutputOverlapsInput(out);
  return why.empty() ? "" : Refusal(out, why);
}

// The refusal of a directory --out that is an input (or holds or sits in one) or exists as
// something else than a directory, "" otherwise; *exists says whether anything is there.
std::string DirectoryOutRefusal(const std::string& out, const std::vector<std::string>& inputs,
                                bool* exists) {
  *exists = false;
  if (const std::string overlap = InputOverlap(out, inputs); !overlap.empty()) return overlap;
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(out, ec);
  *exists = fs::exists(status);
  if (*exists && !fs::is_directory(status)) {
    return Refusal(out, "exists and is not a directory; --out must name a directory");
  }
  return "";
}

// Every file below `dir`, relative to it ("runs/a_encoders.csv"); directories are not listed.
std::set<std::string> FilesUnder(const fs::path& dir) {
  std::set<std::string> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_directory(ec)) files.insert(it->path().lexically_relative(dir).string());
  }
  return files;
}

// The marker of a directory fitcal wrote: "fitcal output: <kind>", then one file per line.
void WriteMarker(const std::string& staged_dir, const std::string& kind) {
  std::string text = std::string("fitcal output: ") + kind + "\n";
  for (const std::string& file : FilesUnder(staged_dir)) text += file + "\n";
  io::WriteFileAtomically((fs::path(staged_dir) / kOutputMarker).string(), text);
}

// The files the marker of `dir` lists when it names `kind`; nullopt without such a marker.
std::optional<std::set<std::string>> MarkedFiles(const fs::path& dir, const std::string& kind) {
  std::ifstream in(dir / kOutputMarker);
  std::string line;
  if (!std::getline(in, line) || line != "fitcal output: " + kind) return std::nullopt;
  std::set<std::string> files{kOutputMarker};
  while (std::getline(in, line)) files.insert(line);
  return files;
}

// A data set written before the marker existed: dataset.yaml, the files it names, and the robot
// and truth YAMLs the simulators write beside it.
std::optional<std::set<std::string>> LegacyDatasetFiles(const fs::path& dir) {
  std::set<std::string> files{"dataset.yaml", "robot.yaml", "truth.yaml", "true_robot.yaml"};
  try {
    const io::NotAnInput probe;
    const YAML::Node root = io::LoadYamlFile((dir / "dataset.yaml").string());
    if (root["robot"] && root["robot"].IsScalar()) files.insert(root["robot"].Scalar());
    for (const YAML::Node& run : root["runs"]) {
      for (const char* key : {"encoders", "ground_truth"}) {
        if (run[key] && run[key].IsScalar()) {
          files.insert(fs::path(run[key].Scalar()).lexically_normal().string());
        }
      }
    }
  } catch (const std::exception&) {
    return std::nullopt;  // no readable dataset.yaml: not recognisably a data set
  }
  return files;
}

// The kind the marker of `dir` names ("data set"), "" without a marker.
std::string MarkedKind(const fs::path& dir) {
  std::ifstream in(dir / kOutputMarker);
  std::string line;
  const std::string prefix = "fitcal output: ";
  if (!std::getline(in, line) || line.compare(0, prefix.size(), prefix) != 0) return "";
  return line.substr(prefix.size());
}

// The first file below `dir` that a fitcal output of `kind` does not hold, "" when none.
std::string ForeignFile(const fs::path& dir, const std::string& kind) {
  std::optional<std::set<std::string>> own = MarkedFiles(dir, kind);
  if (!own && kind == kDatasetKind) own = LegacyDatasetFiles(dir);
  for (const std::string& file : FilesUnder(dir)) {
    if (!own || own->count(file) == 0) return file;
  }
  return "";
}

}  // namespace

// The previous output at `out` read as YAML to see whose it is; nullopt when `out` does not
// exist, a Null node when it is not YAML.
std::optional<YAML::Node> PreviousYaml(const std::string& out) {
  // stat, not fopen: opening a FIFO to probe it would wait for a writer.
  struct stat info {};
  if (::stat(out.c_str(), &info) != 0) return std::nullopt;
  try {
    const io::NotAnInput probe;
    return io::LoadYamlFile(out);
  } catch (const std::exception&) {
    return YAML::Node();  // not YAML at all: refused like any file the command did not write
  }
}

std::string OverwriteRefusal(const std::string& out, const std::string& robot_name) {
  const std::optional<YAML::Node> root = PreviousYaml(out);
  if (!root) return "";
  std::string existing;
  if (root->IsMap() && (*root)["name"] && (*root)["name"].IsScalar()) {
    existing = (*root)["name"].Scalar();
  }
  if (existing == robot_name) return "";
  return out + ": " +
         (existing.empty()
              ? std::string("exists and is not a robot YAML")
              : "holds the calibration of robot '" + existing + "', not '" + robot_name + "'") +
         "; refusing to overwrite it (--force to replace it)";
}

std::string ParameterFileOverwriteRefusal(const std::string& out, const std::string& node_name) {
  const std::optional<YAML::Node> root = PreviousYaml(out);
  if (!root) return "";
  if (root->IsMap() && root->size() == 1 && (*root)[node_name] &&
      (*root)[node_name]["ros__parameters"]) {
    return "";
  }
  return out + ": exists and is not the parameter file of '" + node_name +
         "'; refusing to overwrite it (--force to replace it)";
}

std::string TextOutputOverwriteRefusal(const std::string& out, const std::string& first_line) {
  // stat first: a FIFO or device is refused by OutputFileRefusal, never opened here.
  struct stat info {};
  if (::stat(out.c_str(), &info) != 0) return "";
  std::string line;
  if (S_ISREG(info.st_mode)) {
    const io::NotAnInput probe;
    std::ifstream in(out);
    std::getline(in, line);
  }
  if (line.compare(0, first_line.size(), first_line) == 0) return "";
  return Refusal(out,
                 "exists and is not this command's previous output; refusing to overwrite it "
                 "(--force to replace it)");
}

std::string OutputFileRefusal(const std::string& out, const std::vector<std::string>& inputs) {
  if (out.empty()) return "--out is empty; name the file to write";
  if (const std::string overlap = InputOverlap(out, inputs); !overlap.empty()) return overlap;
  struct stat info {};
  if (::stat(out.c_str(), &info) != 0) return "";
  if (!S_ISREG(info.st_mode)) {
    return Refusal(out,
                   "exists and is not a regular file (a directory, FIFO or device); "
                   "--out must name a file to write");
  }
  return "";
}

std::string OutputDirectoryRefusal(const std::string& out, const std::vector<std::string>& inputs,
                                   const std::set<std::string>& own_names) {
  if (out.empty()) return "--out is empty; name the directory to write";
  bool exists = false;
  if (const std::string refusal = DirectoryOutRefusal(out, inputs, &exists);
      !refusal.empty() || !exists) {
    return refusal;
  }
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    const std::string name = entry.path().filename().string();
    if (own_names.count(name) == 0 && name != kOutputMarker) {
      return Refusal(out, "holds '" + io::OneLine(name, 80) +
                              "', which this command does not write; refusing to replace the "
                              "directory (choose an empty or new --out)");
    }
  }
  return "";
}

void CommitOutputDirectory(io::StagedDirectory& staged, const std::string& out,
                           const std::vector<std::string>& inputs,
                           const std::set<std::string>& own_names) {
  const std::string refusal = OutputDirectoryRefusal(out, inputs, own_names);
  if (!refusal.empty()) throw std::runtime_error(refusal);
  staged.Commit(/*replace_existing=*/true);
}

std::string DirectoryOutputRefusal(const std::string& out, const std::string& kind, bool force,
                                   const std::vector<std::string>& inputs) {
  if (out.empty()) return "--out is empty; name the directory to write the " + kind + " to";
  bool exists = false;
  if (const std::string refusal = DirectoryOutRefusal(out, inputs, &exists);
      !refusal.empty() || !exists) {
    return refusal;
  }
  std::error_code ec;
  if (fs::is_empty(out, ec)) return "";
  if (ForeignFile(out, kind).empty()) return "";  // its own previous output (rule 1)
  const std::string other_kind = MarkedKind(out);
  if (!other_kind.empty() && ForeignFile(out, other_kind).empty()) {
    if (force) return "";
    return Refusal(
        out, "holds a " + other_kind + " fitcal wrote, not a " + kind + "; --force to replace it");
  }
  const std::string foreign = ForeignFile(out, kind);
  return Refusal(out, "holds '" + io::OneLine(foreign, 80) + "', which fitcal did not write as a " +
                          kind +
                          "; refusing to replace the directory, --force or not (choose an empty "
                          "or new --out)");
}

void CommitDirectoryOutput(io::StagedDirectory& staged, const std::string& out,
                           const std::string& kind, bool force,
                           const std::vector<std::string>& inputs) {
  const std::string refusal = DirectoryOutputRefusal(out, kind, force, inputs);
  if (!refusal.empty()) throw std::runtime_error(refusal);
  WriteMarker(staged.path(), kind);
  staged.Commit(/*replace_existing=*/true);
}

std::vector<std::string> DatasetInputs(const io::DatasetIndex& index) {
  std::vector<std::string> inputs{index.directory, index.yaml_path, index.robot_path};
  for (const io::DatasetIndexEntry& run : index.runs) {
    inputs.push_back(run.encoders_path);
    inputs.push_back(run.ground_truth_path);
  }
  return inputs;
}

}  // namespace fitcal::io
