#include "io/atomic_directory.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace fitcal::io {

namespace fs = std::filesystem;

namespace {

std::string MakeTemporarySibling(const std::string& dir) {
  std::string tmpl = fs::path(dir).lexically_normal().string();
  while (tmpl.size() > 1 && tmpl.back() == '/') tmpl.pop_back();
  tmpl += ".tmp-XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  if (mkdtemp(name.data()) == nullptr) {
    throw std::runtime_error(
        dir + ": cannot create a temporary directory beside it: " + std::strerror(errno));
  }
  return name.data();
}

// Puts `tmp` in place of the existing `dir`; afterwards `tmp` names the old directory.
void Exchange(const std::string& tmp, const std::string& dir) {
  if (renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, dir.c_str(), RENAME_EXCHANGE) == 0) return;
  if (errno != EINVAL && errno != ENOSYS) {
    throw std::runtime_error(dir + ": cannot replace it: " + std::strerror(errno));
  }
  const std::string aside = MakeTemporarySibling(dir);
  fs::remove(aside);
  fs::rename(dir, aside);
  fs::rename(tmp, dir);
  fs::rename(aside, tmp);
}

}  // namespace

void WriteDirectoryAtomically(const std::string& dir, bool replace,
                              const std::function<void(const std::string& tmp)>& write) {
  const bool exists = fs::exists(dir);
  if (exists && !replace) throw std::runtime_error(dir + ": exists; refusing to overwrite it");
  if (exists && !fs::is_directory(dir)) {
    throw std::runtime_error(dir + ": exists and is not a directory");
  }
  if (!fs::path(dir).parent_path().empty()) fs::create_directories(fs::path(dir).parent_path());
  const std::string tmp = MakeTemporarySibling(dir);
  try {
    write(tmp);
    fs::permissions(tmp, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                             fs::perms::others_read | fs::perms::others_exec);
    if (exists) {
      Exchange(tmp, dir);
      fs::remove_all(tmp);  // the old directory
    } else {
      fs::rename(tmp, dir);
    }
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);
    throw;
  }
}

}  // namespace fitcal::io
