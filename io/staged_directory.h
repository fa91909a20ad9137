#pragma once
// A directory written whole or not at all, as WriteFileAtomically (atomic_file.h) does for one
// file: everything goes into a hidden temporary sibling `.<target>.tmp-<pid>-XXXXXX`, which Commit
// renames to the target once complete. A failure before Commit (an exception unwinding past the
// object) removes the sibling, so the target is either absent, the previous directory untouched,
// or the new directory complete. An existing target is replaced only when asked
// (replace_existing): the two are swapped in one rename (RENAME_EXCHANGE) and the old one
// removed; where the file system cannot exchange, it is renamed aside first, the new one renamed
// in, then the old one removed (a crash in between leaves a hidden `...tmp-<pid>-old-XXXXXX`
// beside the complete new directory). SIGKILL before Commit leaves the hidden sibling and the
// target as it was; the next writer of the same target removes it (RemoveStaleTemporaries).
// The target must not be, hold or sit inside an input of the process (io/input_registry.h); what
// the process reads back from the sibling before Commit is its own output, not an input.

#include <string>

namespace fitcal::io {

class StagedDirectory {
 public:
  // Creates the temporary sibling (and the target's parent directories). Throws
  // std::runtime_error when they cannot be created.
  explicit StagedDirectory(const std::string& target);
  ~StagedDirectory();  // removes the sibling unless committed
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  // Where to write the files (the temporary sibling).
  const std::string& path() const { return staging_; }
  // Renames the sibling to the target. Throws std::runtime_error when the target exists and
  // !replace_existing, or a rename fails (the sibling is then removed, the target untouched).
  void Commit(bool replace_existing);

 private:
  std::string target_;
  std::string staging_;
  bool committed_ = false;
};

}  // namespace fitcal::io
