#include "io/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/input_registry.h"

namespace fitcal::io {
namespace {

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

// The temporary file of the write in flight, readable from a signal handler: a fixed buffer and a
// flag, set and cleared with the cleanup signals blocked so the handler never sees half a name.
char g_in_flight_path[PATH_MAX + 16];
volatile sig_atomic_t g_has_in_flight = 0;

// A directory being staged (staged_directory.h), so that a cleanup signal removes it and all it
// holds (a data set's runs/ too).
char g_staging_dir[PATH_MAX + 16];
volatile sig_atomic_t g_has_staging_dir = 0;

// One record of getdents64 (linux_dirent64): the name starts at a fixed offset.
struct DirentHeader {
  std::uint64_t ino;
  std::int64_t off;
  unsigned short reclen;
  unsigned char type;
  char name[1];
};

// Removes `name` (relative to `parent_fd`) and, when it is a directory, what it holds down to
// `depth` levels. Only system calls (openat, getdents64, unlinkat, close) and a stack buffer:
// safe in a signal handler, where opendir/nftw (malloc) are not. Entries removed while listing
// may shift the listing, so the directory is listed again until a pass removes nothing.
// Returns whether `name` is gone.
bool RemoveTreeFromHandler(int parent_fd, const char* name, int depth) {
  if (unlinkat(parent_fd, name, 0) == 0) return true;  // a file (or a link)
  const int fd = openat(parent_fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return false;
  alignas(8) char buffer[4096];
  for (bool removed = depth > 0; removed;) {
    removed = false;
    lseek(fd, 0, SEEK_SET);
    for (long n; (n = syscall(SYS_getdents64, fd, buffer, sizeof(buffer))) > 0;) {
      for (long at = 0; at < n;) {
        const char* child = buffer + at + offsetof(DirentHeader, name);
        at += reinterpret_cast<const DirentHeader*>(buffer + at)->reclen;
        if (child[0] == '.' && (child[1] == '\0' || (child[1] == '.' && child[2] == '\0')))
          continue;
        removed = RemoveTreeFromHandler(fd, child, depth - 1) || removed;
      }
    }
  }
  close(fd);
  return unlinkat(parent_fd, name, AT_REMOVEDIR) == 0;
}

// True when `path` lies below the directory being staged.
bool InStagingDirectory(const std::string& path) {
  if (!g_has_staging_dir) return false;
  const std::size_t n = std::strlen(g_staging_dir);
  return path.size() > n + 1 && path.compare(0, n, g_staging_dir) == 0 && path[n] == '/';
}

void RemoveInFlightAndReraise(int signal_number) {
  if (g_has_in_flight) unlink(g_in_flight_path);
  if (g_has_staging_dir) RemoveTreeFromHandler(AT_FDCWD, g_staging_dir, /*depth=*/4);
  signal(signal_number, SIG_DFL);
  raise(signal_number);
}

// Blocks the cleanup signals for its lifetime.
class CleanupSignalsBlocked {
 public:
  CleanupSignalsBlocked() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : kCleanupSignals) sigaddset(&set, s);
    pthread_sigmask(SIG_BLOCK, &set, &previous_);
  }
  ~CleanupSignalsBlocked() { pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }
  CleanupSignalsBlocked(const CleanupSignalsBlocked&) = delete;
  CleanupSignalsBlocked& operator=(const CleanupSignalsBlocked&) = delete;

 private:
  sigset_t previous_;
};

// Creates the temporary file and records it as in flight; returns its descriptor and path.
int CreateTemporary(const std::string& path, std::string* tmp_path) {
  std::string tmpl = TemporaryPrefix(path) + "XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const CleanupSignalsBlocked blocked;
  const int fd = mkstemp(name.data());
  if (fd < 0) {
    throw std::runtime_error(path + ": cannot create a file beside it: " + std::strerror(errno));
  }
  *tmp_path = name.data();
  if (tmp_path->size() < sizeof(g_in_flight_path)) {
    std::memcpy(g_in_flight_path, tmp_path->c_str(), tmp_path->size() + 1);
    g_has_in_flight = 1;
  }
  return fd;
}

}  // namespace

std::string TemporaryPrefix(const std::string& path) {
  const std::filesystem::path p(path);
  const std::filesystem::path dir = p.parent_path();
  const std::string hidden = "." + p.filename().string() + ".tmp-" + std::to_string(getpid()) + "-";
  return dir.empty() ? hidden : (dir / hidden).string();
}

void RemoveStaleTemporaries(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const std::string prefix = "." + p.filename().string() + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    // ".<name>.tmp-<pid>-XXXXXX": the writer's pid, then the unique suffix.
    const std::size_t dash = name.find('-', prefix.size());
    if (dash == std::string::npos) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid <= 0 || (kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
}

namespace {

// Writes `contents` to a new temporary beside `path` (flushed to disk) and returns its name;
// throws std::runtime_error, the temporary removed, when the output may not or cannot be written.
std::string WriteTemporary(const std::string& path, std::string_view contents) {
  if (const std::string overlap = OutputOverlapsInput(path); !overlap.empty()) {
    throw std::runtime_error(path + ": " + overlap);
  }
  // A staged directory is new and ours: nothing stale in it (and a data set writer would list it
  // once per file).
  if (!InStagingDirectory(path)) RemoveStaleTemporaries(path);
  std::string tmp_path;
  const int fd = CreateTemporary(path, &tmp_path);
  const char* data = contents.data();
  std::size_t left = contents.size();
  int error = 0;
  while (left > 0) {
    const ssize_t n = write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      error = errno;  // EFBIG under a file-size limit (SIGXFSZ ignored), ENOSPC, EIO
      break;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  if (error == 0 && (fchmod(fd, 0644) != 0 || fsync(fd) != 0)) error = errno;
  if (close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    const CleanupSignalsBlocked blocked;
    g_has_in_flight = 0;
    unlink(tmp_path.c_str());
    throw std::runtime_error(path + ": cannot write: " + std::strerror(error));
  }
  return tmp_path;
}

// Renames the temporary over `path`; throws std::runtime_error (the temporary removed).
void RenameTemporary(const std::string& tmp_path, const std::string& path) {
  const CleanupSignalsBlocked blocked;
  g_has_in_flight = 0;
  if (std::rename(tmp_path.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    unlink(tmp_path.c_str());
    throw std::runtime_error(path + ": cannot write: " + reason);
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path, std::string_view contents) {
  const std::string tmp_path = WriteTemporary(path, contents);
  StopHereForTests("temporary-written");
  RenameTemporary(tmp_path, path);
}

void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> temporaries;
  auto remove_from = [&](std::size_t first) {
    for (std::size_t k = first; k < temporaries.size(); ++k) unlink(temporaries[k].c_str());
  };
  try {
    for (const auto& [path, contents] : files)
      temporaries.push_back(WriteTemporary(path, contents));
  } catch (...) {
    remove_from(0);
    throw;
  }
  StopHereForTests("temporaries-written");
  for (std::size_t k = 0; k < files.size(); ++k) {
    try {
      RenameTemporary(temporaries[k], files[k].first);
    } catch (...) {
      remove_from(k + 1);
      throw;
    }
  }
}

void SetStagingDirectoryForSignals(const std::string& dir) {
  const CleanupSignalsBlocked blocked;
  g_has_staging_dir = 0;
  if (!dir.empty() && dir.size() < sizeof(g_staging_dir)) {
    std::memcpy(g_staging_dir, dir.c_str(), dir.size() + 1);
    g_has_staging_dir = 1;
  }
}

void RemoveTemporaryFilesOnSignals() {
  for (int s : kCleanupSignals) {
    struct sigaction current;
    if (sigaction(s, nullptr, &current) != 0 || current.sa_handler == SIG_IGN) continue;
    struct sigaction action;
    std::memset(&action, 0, sizeof(action));
    action.sa_handler = RemoveInFlightAndReraise;
    sigemptyset(&action.sa_mask);
    for (int other : kCleanupSignals) sigaddset(&action.sa_mask, other);
    sigaction(s, &action, nullptr);
  }
}

void StopHereForTests(const char* stage) {
  const char* wanted = std::getenv("FITCAL_TEST_STOP_AT");
  if (wanted != nullptr && std::strcmp(wanted, stage) == 0) raise(SIGSTOP);
}

}  // namespace fitcal::io
