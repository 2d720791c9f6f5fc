// SPDX-License-Identifier: MIT
#pragma once
// Rank 0 of an MPI run (issue 15) writes a new local dataset into a hidden staging folder beside it and moves it
// into place only once every rank has finished: a run that dies (a rank killed, an exception, MPI_Abort) leaves
// no dataset under the name asked for, only `.groundplan-partial-PID/` (removed on an orderly failure).
#include <string>

namespace groundplan::output {

class StagedOutput {
 public:
  /// Staged when `dst` is a local path that does not exist yet (an existing dataset that -append, -update or
  /// -overwrite names, /vsi paths and database connections are written in place).
  explicit StagedOutput(const std::string& dst);
  ~StagedOutput();  // removes the staging folder and what is in it unless committed
  StagedOutput(const StagedOutput&) = delete;
  StagedOutput& operator=(const StagedOutput&) = delete;
  bool staged() const { return !stage_.empty(); }
  /// Where to write: dst itself, or the same name inside the staging folder.
  const std::string& path() const { return path_; }
  /// Moves everything written (the dataset and its side files) into dst's folder. Throws Error on failure.
  void commit();

 private:
  std::string dst_, path_, stage_, parent_;
};

}  // namespace groundplan::output
