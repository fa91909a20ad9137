#include "io/input_registry.h"

#include <sys/stat.h>

#include <atomic>
#include <filesystem>
#include <mutex>

#include "io/input_error.h"

namespace fitcal::io {
namespace {

namespace fs = std::filesystem;

std::atomic<bool> g_enabled{false};
std::mutex g_mutex;
std::vector<std::string> g_inputs;  // guarded by g_mutex
thread_local bool t_probing = false;

// The absolute path with links and ".." resolved as far as the path exists: two spellings of
// one place compare equal.
fs::path Resolved(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) p = fs::absolute(path, ec).lexically_normal();
  return p;
}

// True when `inner` is `outer` or lies below it (component by component: /a/bc is not in /a/b).
bool IsWithin(const fs::path& inner, const fs::path& outer) {
  std::string o = outer.string();
  while (o.size() > 1 && o.back() == '/') o.pop_back();
  const std::string i = inner.string();
  return i == o || (i.size() > o.size() && i.compare(0, o.size(), o) == 0 &&
                    (o == "/" || i[o.size()] == '/'));
}

bool SameInode(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  return ::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

bool IsDirectory(const std::string& path) {
  struct stat s {};
  return ::stat(path.c_str(), &s) == 0 && S_ISDIR(s.st_mode);
}

}  // namespace

void EnableInputGuard() { g_enabled = true; }

NotAnInput::NotAnInput() : previous_(t_probing) { t_probing = true; }
NotAnInput::~NotAnInput() { t_probing = previous_; }

void RegisterInputFile(const std::string& path) {
  if (!g_enabled || t_probing || path.empty()) return;
  const std::lock_guard<std::mutex> lock(g_mutex);
  g_inputs.push_back(path);
}

void RegisterInputDirectory(const std::string& path) { RegisterInputFile(path); }

std::string OutputOverlapsInputs(const std::string& out, const std::vector<std::string>& inputs) {
  if (out.empty()) return "";
  const fs::path out_path = Resolved(out);
  // Three passes, so that the most direct relation is named: the output is an input file, holds
  // an input (or is an input directory), sits inside an input directory.
  for (const std::string& input : inputs) {
    if (input.empty() || IsDirectory(input)) continue;
    if (Resolved(input) == out_path || SameInode(out, input)) {
      return "is the input file " + OneLine(input, 200) +
             "; writing the output there would destroy it (choose another --out)";
    }
  }
  for (const std::string& input : inputs) {
    if (!input.empty() && IsWithin(Resolved(input), out_path)) {
      return "holds the input " + OneLine(input, 200) +
             "; the output would replace it (choose another --out)";
    }
  }
  for (const std::string& input : inputs) {
    if (!input.empty() && IsDirectory(input) && IsWithin(out_path, Resolved(input))) {
      return "sits inside the input directory " + OneLine(input, 200) +
             "; write outputs outside the inputs (choose another --out)";
    }
  }
  return "";
}

std::string OutputOverlapsInput(const std::string& out) {
  if (!g_enabled) return "";
  std::vector<std::string> inputs;
  {
    const std::lock_guard<std::mutex> lock(g_mutex);
    inputs = g_inputs;
  }
  return OutputOverlapsInputs(out, inputs);
}

}  // namespace fitcal::io
