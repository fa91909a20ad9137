#include "io/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "io/input_registry.h"

namespace fitcal::io {
namespace {

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

// The temporary files of the writes in flight, readable from a signal handler: fixed buffers, one
// per writer thread at a time (a data set's runs are written by several threads at once), each
// claimed and released through its atomic state, so the handler never sees half a name. A write
// finding every slot taken still happens; its temporary is then left to RemoveStaleTemporaries
// (or to the staged directory's removal, where nearly all parallel writes go).
constexpr int kInFlightSlots = 64;
struct InFlightSlot {
  std::atomic<int> state{0};  // 0 free, 1 being filled or emptied, 2 holds a name
  char path[PATH_MAX + 16];
};
InFlightSlot g_in_flight[kInFlightSlots];

// A directory being staged (staged_directory.h), so that a cleanup signal removes it and all it
// holds (a data set's runs/ too), and the name it is first moved to: writer threads that go on
// while the handler runs then find no directory to add files to (their paths name the old one),
// and the handler removes a tree nobody writes into.
char g_staging_dir[PATH_MAX + 16];
char g_staging_dir_aside[PATH_MAX + 32];
volatile sig_atomic_t g_has_staging_dir = 0;

// One cleanup per process: a second signal (another thread, another kind) while the first is
// handled leaves it to the first, which ends the process.
std::atomic_flag g_cleaning_up = ATOMIC_FLAG_INIT;

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
  if (g_cleaning_up.test_and_set()) return;
  for (InFlightSlot& slot : g_in_flight) {
    if (slot.state.load() == 2) unlink(slot.path);
  }
  if (g_has_staging_dir) {
    const bool aside = renameat(AT_FDCWD, g_staging_dir, AT_FDCWD, g_staging_dir_aside) == 0;
    const char* tree = aside ? g_staging_dir_aside : g_staging_dir;
    // A writer's open file may still gain an entry just as the tree is listed: a bounded number
    // of passes, never a loop that waits on other threads.
    for (int pass = 0; pass < 8 && !RemoveTreeFromHandler(AT_FDCWD, tree, /*depth=*/4); ++pass) {
    }
  }
  signal(signal_number, SIG_DFL);
  raise(signal_number);
}

// Claims a slot for `path` (-1 when all are taken).
int ClaimInFlightSlot(const std::string& path) {
  if (path.size() >= sizeof(InFlightSlot::path)) return -1;
  for (int k = 0; k < kInFlightSlots; ++k) {
    int expected = 0;
    if (!g_in_flight[k].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_in_flight[k].path, path.c_str(), path.size() + 1);
    g_in_flight[k].state.store(2);
    return k;
  }
  return -1;
}

void ReleaseInFlightSlot(int slot) {
  if (slot >= 0) g_in_flight[slot].state.store(0);
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

// Creates the temporary file and records it as in flight (*slot); returns its descriptor and path.
int CreateTemporary(const std::string& path, std::string* tmp_path, int* slot) {
  std::string tmpl = TemporaryPrefix(path) + "XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const CleanupSignalsBlocked blocked;
  const int fd = mkstemp(name.data());
  if (fd < 0) {
    throw std::runtime_error(path + ": cannot create a file beside it: " + std::strerror(errno));
  }
  *tmp_path = name.data();
  *slot = ClaimInFlightSlot(*tmp_path);
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

// A temporary written and not yet renamed: its name and its in-flight slot.
struct Temporary {
  std::string path;
  int slot = -1;
};

// Writes `contents` to a new temporary beside `path` (flushed to disk) and returns it; throws
// std::runtime_error, the temporary removed, when the output may not or cannot be written.
Temporary WriteTemporary(const std::string& path, std::string_view contents) {
  if (const std::string overlap = OutputOverlapsInput(path); !overlap.empty()) {
    throw std::runtime_error(path + ": " + overlap);
  }
  // A staged directory is new and ours: nothing stale in it (and a data set writer would list it
  // once per file).
  if (!InStagingDirectory(path)) RemoveStaleTemporaries(path);
  std::string tmp_path;
  int slot = -1;
  const int fd = CreateTemporary(path, &tmp_path, &slot);
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
    ReleaseInFlightSlot(slot);
    unlink(tmp_path.c_str());
    throw std::runtime_error(path + ": cannot write: " + std::strerror(error));
  }
  return {tmp_path, slot};
}

// Renames the temporary over `path`; throws std::runtime_error (the temporary removed).
void RenameTemporary(const Temporary& tmp, const std::string& path) {
  const CleanupSignalsBlocked blocked;
  ReleaseInFlightSlot(tmp.slot);
  if (std::rename(tmp.path.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    unlink(tmp.path.c_str());
    throw std::runtime_error(path + ": cannot write: " + reason);
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path, std::string_view contents) {
  const Temporary tmp = WriteTemporary(path, contents);
  StopHereForTests("temporary-written");
  RenameTemporary(tmp, path);
}

void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<Temporary> temporaries;
  auto remove_from = [&](std::size_t first) {
    for (std::size_t k = first; k < temporaries.size(); ++k) {
      const CleanupSignalsBlocked blocked;
      ReleaseInFlightSlot(temporaries[k].slot);
      unlink(temporaries[k].path.c_str());
    }
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
  // "<staging>-x": still ".<name>.tmp-<pid>-...", so a SIGKILL during the cleanup leaves what
  // the next writer removes (RemoveStaleTemporaries).
  const std::string aside = dir + "-x";
  if (!dir.empty() && aside.size() < sizeof(g_staging_dir)) {
    std::memcpy(g_staging_dir, dir.c_str(), dir.size() + 1);
    std::memcpy(g_staging_dir_aside, aside.c_str(), aside.size() + 1);
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
  if (wanted == nullptr) return;
  // "<stage>" or "<stage>#<n>": the n-th time any thread passes the stage (1 by default), once
  // per process, so that threads passing it after the test resumed the process cannot stop it
  // again (the stop would outlast the signal the test delivers).
  const char* hash = std::strchr(wanted, '#');
  const std::size_t length = hash ? static_cast<std::size_t>(hash - wanted) : std::strlen(wanted);
  if (length != std::strlen(stage) || std::strncmp(wanted, stage, length) != 0) return;
  static std::atomic<long> passes{0};
  const long n = hash ? std::strtol(hash + 1, nullptr, 10) : 1;
  if (++passes == n) raise(SIGSTOP);
}

}  // namespace fitcal::io
