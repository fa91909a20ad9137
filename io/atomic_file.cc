#include "io/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace fitcal::io {
namespace {

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

// The temporary file of the write in flight, readable from a signal handler: a fixed buffer and a
// flag, set and cleared with the cleanup signals blocked so the handler never sees half a name.
char g_in_flight_path[PATH_MAX + 16];
volatile sig_atomic_t g_has_in_flight = 0;

// A directory being staged (staged_directory.h) and the files already renamed into it, so that a
// cleanup signal removes it too (unlink and rmdir only: async-signal-safe).
constexpr int kMaxStagedFiles = 32;
char g_staging_dir[PATH_MAX + 16];
char g_staged_files[kMaxStagedFiles][PATH_MAX + 16];
volatile sig_atomic_t g_num_staged_files = 0;
volatile sig_atomic_t g_has_staging_dir = 0;

void RemoveInFlightAndReraise(int signal_number) {
  if (g_has_in_flight) unlink(g_in_flight_path);
  if (g_has_staging_dir) {
    for (int i = 0; i < g_num_staged_files; ++i) unlink(g_staged_files[i]);
    rmdir(g_staging_dir);
  }
  signal(signal_number, SIG_DFL);
  raise(signal_number);
}

bool InStagingDirectory(const std::string& path) {
  if (!g_has_staging_dir) return false;
  const std::size_t n = std::strlen(g_staging_dir);
  return path.size() > n + 1 && path.compare(0, n, g_staging_dir) == 0 && path[n] == '/' &&
         path.find('/', n + 1) == std::string::npos;
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
  std::string tmpl = path + ".tmp-XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const CleanupSignalsBlocked blocked;
  const int fd = mkstemp(name.data());
  if (fd < 0) {
    throw std::runtime_error(path + ": cannot create temporary file: " + std::strerror(errno));
  }
  *tmp_path = name.data();
  if (tmp_path->size() < sizeof(g_in_flight_path)) {
    std::memcpy(g_in_flight_path, tmp_path->c_str(), tmp_path->size() + 1);
    g_has_in_flight = 1;
  }
  return fd;
}

}  // namespace

void WriteFileAtomically(const std::string& path, std::string_view contents) {
  std::string tmp_path;
  const int fd = CreateTemporary(path, &tmp_path);
  const char* data = contents.data();
  std::size_t left = contents.size();
  bool ok = true;
  while (left > 0) {
    const ssize_t n = write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      break;
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  const int saved_errno = errno;
  ok = ok && fchmod(fd, 0644) == 0 && fsync(fd) == 0;
  ok = (close(fd) == 0) && ok;
  StopHereForTests("temporary-written");
  const CleanupSignalsBlocked blocked;
  g_has_in_flight = 0;
  if (!ok || std::rename(tmp_path.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(ok ? errno : saved_errno);
    unlink(tmp_path.c_str());
    throw std::runtime_error(path + ": cannot write: " + reason);
  }
  if (InStagingDirectory(path) && g_num_staged_files < kMaxStagedFiles &&
      path.size() < sizeof(g_staged_files[0])) {
    std::memcpy(g_staged_files[g_num_staged_files], path.c_str(), path.size() + 1);
    g_num_staged_files = g_num_staged_files + 1;
  }
}

void SetStagingDirectoryForSignals(const std::string& dir) {
  const CleanupSignalsBlocked blocked;
  g_num_staged_files = 0;
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
