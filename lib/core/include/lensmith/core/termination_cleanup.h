// Leaving nothing half-written when the process is told to stop.
//
// A render farm stops a task with SIGTERM (Slurm's scancel, a time limit, a pre-empted node), a user
// with Ctrl-C (SIGINT) or by closing the terminal (SIGHUP). Every output is written to a hidden
// temporary file and renamed into place (text_file.h), so a stopped process never leaves a partial
// file under an output's name; these handlers also remove the temporary files of the writes in
// progress, so nothing is left at all, and then let the signal end the process as it would have
// (the exit status still says which signal: 128 + 15 for SIGTERM). SIGKILL cannot be caught: after
// one, a hidden `.NAME.tmpNNNN` file may remain, never a frame.
#pragma once

#include <string>

namespace lensmith {

// Installs the handlers for SIGTERM, SIGINT and SIGHUP (once; later calls do nothing). A program
// calls it at the start of main.
void remove_temporaries_on_termination();

// Marks a temporary file as being written (removed if the process is stopped) until the returned
// guard is destroyed. Lock-free and allocation-free in the handler; at most 64 files at once (more
// are written but not tracked).
class TemporaryFileGuard {
 public:
  explicit TemporaryFileGuard(const std::string& path);
  ~TemporaryFileGuard();
  TemporaryFileGuard(const TemporaryFileGuard&) = delete;
  TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace lensmith
