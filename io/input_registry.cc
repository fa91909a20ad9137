#include "io/input_registry.h"

#include <sys/stat.h>

#include <atomic>
#include <filesystem>
#include <map>
#include <set>
#include <mutex>

#include "io/input_error.h"

namespace fitcal::io {
namespace {

namespace fs = std::filesystem;

// One input, resolved once when it is recorded (a data set writer checks hundreds of outputs
// against hundreds of inputs: no path is resolved twice).
struct Input {
  std::string given;  // as the command named it, for messages
  std::string resolved;
  bool is_directory = false;
  bool has_inode = false;
  dev_t device = 0;
  ino_t inode = 0;
};

std::atomic<bool> g_enabled{false};
std::mutex g_mutex;
std::map<std::string, Input> g_inputs;  // by the given path; guarded by g_mutex
std::multiset<std::string> g_staged_outputs;  // resolved staging directories; guarded by g_mutex
thread_local bool t_probing = false;

// The absolute path with links and ".." resolved as far as the path exists: two spellings of
// one place compare equal.
std::string Resolved(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) p = fs::absolute(path, ec).lexically_normal();
  std::string s = p.string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

Input Describe(const std::string& path) {
  Input input;
  input.given = path;
  input.resolved = Resolved(path);
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0) {
    input.has_inode = true;
    input.device = info.st_dev;
    input.inode = info.st_ino;
    input.is_directory = S_ISDIR(info.st_mode);
  }
  return input;
}

// True when `inner` is `outer` or lies below it (component by component: /a/bc is not in /a/b).
bool IsWithin(const std::string& inner, const std::string& outer) {
  return inner == outer ||
         (inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
          (outer == "/" || inner[outer.size()] == '/'));
}

// Three passes, so that the most direct relation is named: the output is an input file, holds
// an input (or is an input directory), sits inside an input directory.
std::string Overlap(const std::string& out, const std::vector<Input>& inputs) {
  if (out.empty()) return "";
  const Input output = Describe(out);
  for (const Input& in : inputs) {
    if (in.is_directory) continue;
    if (in.resolved == output.resolved ||
        (in.has_inode && output.has_inode && in.device == output.device &&
         in.inode == output.inode)) {
      return "is the input file " + OneLine(in.given, 200) +
             "; writing the output there would destroy it (choose another --out)";
    }
  }
  for (const Input& in : inputs) {
    if (IsWithin(in.resolved, output.resolved)) {
      return "holds the input " + OneLine(in.given, 200) +
             "; the output would replace it (choose another --out)";
    }
  }
  for (const Input& in : inputs) {
    if (in.is_directory && IsWithin(output.resolved, in.resolved)) {
      return "sits inside the input directory " + OneLine(in.given, 200) +
             "; write outputs outside the inputs (choose another --out)";
    }
  }
  return "";
}

}  // namespace

void EnableInputGuard() { g_enabled = true; }

NotAnInput::NotAnInput() : previous_(t_probing) { t_probing = true; }
NotAnInput::~NotAnInput() { t_probing = previous_; }

void RegisterInput(const std::string& path) {
  if (!g_enabled || t_probing || path.empty()) return;
  {
    const std::lock_guard<std::mutex> lock(g_mutex);
    if (g_inputs.count(path) > 0) return;
  }
  Input input = Describe(path);  // outside the lock: system calls
  const std::lock_guard<std::mutex> lock(g_mutex);
  for (const std::string& staged : g_staged_outputs) {
    if (IsWithin(input.resolved, staged)) return;  // the process's own output, read back
  }
  g_inputs.emplace(path, std::move(input));
}

void BeginStagedOutput(const std::string& staging_dir) {
  std::string resolved = Resolved(staging_dir);
  const std::lock_guard<std::mutex> lock(g_mutex);
  g_staged_outputs.insert(std::move(resolved));
}

void EndStagedOutput(const std::string& staging_dir) {
  std::string resolved = Resolved(staging_dir);
  const std::lock_guard<std::mutex> lock(g_mutex);
  if (const auto it = g_staged_outputs.find(resolved); it != g_staged_outputs.end()) {
    g_staged_outputs.erase(it);
  }
}

std::string OutputOverlapsInputs(const std::string& out, const std::vector<std::string>& inputs) {
  std::vector<Input> described;
  for (const std::string& path : inputs) {
    if (!path.empty()) described.push_back(Describe(path));
  }
  return Overlap(out, described);
}

std::string OutputOverlapsInput(const std::string& out) {
  if (!g_enabled) return "";
  std::vector<Input> inputs;
  {
    const std::lock_guard<std::mutex> lock(g_mutex);
    for (const auto& [path, input] : g_inputs) inputs.push_back(input);
  }
  return Overlap(out, inputs);
}

}  // namespace fitcal::io
