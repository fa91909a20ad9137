#include "io/staged_directory.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "io/atomic_file.h"
#include "io/input_registry.h"

namespace fitcal::io {
namespace {

namespace fs = std::filesystem;

// mkdtemp on `<prefix>XXXXXX`: the name is unique and the directory is ours (mode 0700 until the
// files are in; the rename keeps it, so it is widened to the usual 0755 before).
std::string MakeUniqueDirectory(const std::string& prefix, const std::string& target) {
  std::string pattern = prefix + "XXXXXX";
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  if (mkdtemp(name.data()) == nullptr) {
    throw std::runtime_error(target +
                             ": cannot create a directory beside it: " + std::strerror(errno));
  }
  return name.data();
}

// Whatever the command checked, a directory never replaces, holds or sits inside what was read
// (io/input_registry.h).
void ThrowIfAnInput(const std::string& target) {
  if (const std::string overlap = OutputOverlapsInput(target); !overlap.empty()) {
    throw std::runtime_error(target + ": " + overlap);
  }
}

}  // namespace

StagedDirectory::StagedDirectory(const std::string& target) {
  fs::path t = fs::path(target).lexically_normal();
  if (!t.has_filename()) t = t.parent_path();  // "out/" names the directory "out"
  target_ = t.string();
  ThrowIfAnInput(target_);
  std::error_code ec;
  if (t.has_parent_path()) fs::create_directories(t.parent_path(), ec);
  if (ec) throw std::runtime_error(target_ + ": cannot create its parent: " + ec.message());
  RemoveStaleTemporaries(target_);  // a writer killed before (SIGKILL) left its staging behind
  staging_ = MakeUniqueDirectory(TemporaryPrefix(target_), target_);
  BeginStagedOutput(staging_);  // read back before the rename, it is still not an input
  SetStagingDirectoryForSignals(staging_);
  fs::permissions(staging_,
                  fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                      fs::perms::others_read | fs::perms::others_exec,
                  ec);
}

StagedDirectory::~StagedDirectory() {
  SetStagingDirectoryForSignals("");
  EndStagedOutput(staging_);
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

void StagedDirectory::Commit(bool replace_existing) {
  // From here a signal leaves the complete staged directory (and perhaps the previous one moved
  // aside), never a removed staging directory with the target moved away.
  SetStagingDirectoryForSignals("");
  ThrowIfAnInput(target_);
  std::error_code ec;
  const bool exists = fs::exists(target_, ec);
  if (exists && !replace_existing) {
    throw std::runtime_error(target_ + ": exists; refusing to replace it (--force to replace it)");
  }
  // An existing target is swapped with the staged directory in one step (renameat2
  // RENAME_EXCHANGE: never a moment without the target); where the file system cannot exchange,
  // it is moved aside first (a moment without it, never a mixed one).
  std::string aside;
  if (exists) {
    if (renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
      committed_ = true;
      fs::remove_all(staging_, ec);  // now the previous directory
      return;
    }
    aside = MakeUniqueDirectory(TemporaryPrefix(target_) + "old-", target_);
    fs::remove(aside, ec);  // only the unique name is wanted: rename needs it free or empty
    fs::rename(target_, aside, ec);
    if (ec) throw std::runtime_error(target_ + ": cannot move it aside: " + ec.message());
  }
  fs::rename(staging_, target_, ec);
  if (ec) {
    if (!aside.empty()) {
      std::error_code back;
      fs::rename(aside, target_, back);
    }
    throw std::runtime_error(target_ +
                             ": cannot rename the new directory into place: " + ec.message());
  }
  committed_ = true;
  if (!aside.empty()) fs::remove_all(aside, ec);
}

}  // namespace fitcal::io
