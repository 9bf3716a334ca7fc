// A folder written whole beside its place and then renamed into it (the fit folder,
// fit_folder.h), so that a reader of DIR sees the previous folder or the new one, never a mix,
// and several writers of one DIR leave one writer's folder whole:
//   - the files are written into a new folder made exclusively beside DIR (same parent, a unique
//     hidden name: core/atomic_write.h's temporary_sibling), each opened with O_CREAT | O_EXCL |
//     O_NOFOLLOW relative to that folder, so nothing is ever written through a link;
//   - commit() swaps it with DIR in one step (Linux renameat2 RENAME_EXCHANGE), or renames it
//     to DIR when there is none (RENAME_NOREPLACE), then removes the previous folder's files;
//     where the file system has no exchange, the previous folder is renamed away and the new
//     one renamed in: between the two renames, for the time of one rename, there is no DIR;
//   - until commit() succeeds DIR is untouched, and the new folder is removed when the
//     StagedFolder goes (a failed write leaves the previous state and no temporary folder).
// DIR may be missing, or a folder holding only the files the caller names as replaceable (a
// previous fit folder): a folder holding anything else is refused, never removed. A DIR that is
// a link to a folder stands for the folder it names. POSIX only, like the command line.
#pragma once

#include <string>
#include <vector>

namespace softdeca::cli {

class StagedFolder {
 public:
  // Makes DIR's parent folders and the new folder beside DIR. Throws std::runtime_error naming
  // the problem (DIR is a file, DIR holds other files, the parent cannot be written).
  StagedFolder(const std::string& dir, std::vector<std::string> replaceable);
  ~StagedFolder();  // removes the new folder unless committed
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  // The new folder, for writers that take a path (the library's own atomic save).
  const std::string& path() const { return temp_; }
  // A new file `name` in the new folder (never an existing file, never through a link).
  void write(const std::string& name, const std::string& bytes);
  // Puts the new folder at DIR; throws std::runtime_error, leaving DIR as it was, on failure.
  void commit();

 private:
  void check_replaceable(const std::string& folder) const;
  void remove_previous(const std::string& previous) const;

  std::string dir_, temp_;
  std::vector<std::string> replaceable_;
  int fd_ = -1;  // the new folder, opened without following a link
  bool committed_ = false;
};

}  // namespace softdeca::cli
