#include "tools/output_guard.h"

#include <sys/stat.h>

#include <exception>
#include <filesystem>
#include <stdexcept>

#include "io/input_error.h"
#include "io/yaml_reader.h"

namespace fitcal::tools {

namespace fs = std::filesystem;

namespace {

bool SameFile(const struct stat& a, const std::string& path) {
  struct stat b {};
  return ::stat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

// The input that `out` is (by device and inode, so links and "./a" count), or "".
std::string InputAt(const std::string& out, const std::vector<std::string>& inputs) {
  struct stat info {};
  if (::stat(out.c_str(), &info) != 0) return "";
  for (const std::string& input : inputs) {
    if (SameFile(info, input)) return input;
  }
  return "";
}

std::string Refusal(const std::string& out, const std::string& why) {
  return io::OneLine(out, 200) + ": " + why;
}

}  // namespace

std::string OverwriteRefusal(const std::string& out, const std::string& robot_name) {
  // stat, not fopen: opening a FIFO to probe it would wait for a writer.
  struct stat info {};
  if (::stat(out.c_str(), &info) != 0) return "";
  std::string existing;
  try {
    const YAML::Node root = io::LoadYamlFile(out);
    if (root.IsMap() && root["name"] && root["name"].IsScalar()) existing = root["name"].Scalar();
  } catch (const std::exception&) {
    // Not YAML at all: refused below like any file that is not a robot YAML.
  }
  if (existing == robot_name) return "";
  return out + ": " +
         (existing.empty()
              ? std::string("exists and is not a robot YAML")
              : "holds the calibration of robot '" + existing + "', not '" + robot_name + "'") +
         "; refusing to overwrite it (--force to replace it)";
}

std::string OutputFileRefusal(const std::string& out, const std::vector<std::string>& inputs) {
  struct stat info {};
  if (::stat(out.c_str(), &info) != 0) return "";
  if (!S_ISREG(info.st_mode)) {
    return Refusal(out,
                   "exists and is not a regular file (a directory, FIFO or device); "
                   "--out must name a file to write");
  }
  const std::string input = InputAt(out, inputs);
  if (!input.empty()) {
    return Refusal(out, "is the input file " + io::OneLine(input, 200) +
                            "; writing the output there would destroy it (choose another --out)");
  }
  return "";
}

std::string OutputDirectoryRefusal(const std::string& out, const std::vector<std::string>& inputs,
                                   const std::set<std::string>& own_names) {
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(out, ec);
  if (!fs::exists(status)) return "";
  if (!fs::is_directory(status)) {
    return Refusal(out, "exists and is not a directory; --out must name a directory");
  }
  for (const std::string& input : inputs) {
    fs::path p = fs::weakly_canonical(input, ec);
    const fs::path dir = fs::weakly_canonical(out, ec);
    for (; !p.empty() && p != p.parent_path(); p = p.parent_path()) {
      if (p == dir) {
        return Refusal(out, "holds the input " + io::OneLine(input, 200) +
                                "; the output directory would replace it (choose another --out)");
      }
    }
  }
  for (const auto& entry : fs::directory_iterator(out, ec)) {
    const std::string name = entry.path().filename().string();
    if (own_names.count(name) == 0) {
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

std::vector<std::string> DatasetInputs(const io::DatasetIndex& index) {
  std::vector<std::string> inputs{index.yaml_path, index.robot_path};
  for (const io::DatasetIndexEntry& run : index.runs) {
    inputs.push_back(run.encoders_path);
    inputs.push_back(run.ground_truth_path);
  }
  return inputs;
}

}  // namespace fitcal::tools
