// SPDX-License-Identifier: MIT
#pragma once
// `mpirun -np N groundplan ...` (issue 15 stage 2): the ranks of the tiled run talk through MPI. Built only with
// GROUNDPLAN_MPI (CMake); without mpirun (no Open MPI launcher in the environment) MPI is never initialised and
// the CLI is the one-process CLI.
#include <groundplan/gis/tiled.h>

#include <mpi.h>

#include <array>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace groundplan::cli {

class MpiExchange final : public gis::TileExchange {
 public:
  /// MPI_Init; throws Error when MPI cannot start.
  MpiExchange(int* argc, char*** argv);
  /// MPI_Finalize (after a barrier: a rank that died makes mpirun end the others first).
  ~MpiExchange() override;
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  /// The ranks of the job on this rank's host (this one included): they share its cores.
  int ranks_on_host() const { return host_ranks_; }
  std::vector<char> allgather(const std::vector<char>& mine, std::vector<std::uint64_t>* sizes = nullptr) override;
  void send(int to, const std::vector<char>& bytes) override;
  std::vector<char> receive(int from) override;
  /// Progress words: point to point with a tag of their own (kProgressTag), so they never match the run's sends.
  void tell_progress(std::uint64_t bytes_read, bool last) override;
  void heard_progress(bool until_last, const std::function<void(std::uint64_t)>& more) override;
  /// Rank 0's `text` on every rank (collective). A step of the CLI's own before the tiled run: unlike allgather,
  /// not counted by GROUNDPLAN_MPI_TEST_FAIL (whose plain form fails at the run's second allgather).
  std::string broadcast(const std::string& text);
  /// Every rank's `mine`, in rank order (collective; not counted by the test hook either).
  std::vector<int> every_rank(int mine);
  /// Waits for every rank (collective).
  void barrier();
  /// Ends every rank of the job at once (MPI_Abort), after saying why on stderr. Does not return.
  [[noreturn]] void abort(const std::string& why, int code = 1);
  /// A named point where GROUNDPLAN_MPI_TEST_FAIL=RANK:HOW@POINT makes this rank fail (tests only; see the .cpp).
  void test_point(const std::string& point);
  /// True where GROUNDPLAN_MPI_TEST_FAIL=RANK:pretend@POINT names this rank and `point` (tests only): a condition a
  /// test on one host cannot make otherwise (point "shared": this rank does not see the destination's folder).
  bool test_pretends(const std::string& point) const;

 private:
  int rank_ = 0, size_ = 1, host_ranks_ = 1;
  int calls_ = 0;  // for GROUNDPLAN_MPI_TEST_FAIL
  // tell_progress: words sent and not known to be delivered yet (a word's buffer lives until then)
  std::deque<std::pair<std::array<std::uint64_t, 2>, MPI_Request>> told_;
  // heard_progress (rank 0): each rank's latest count, and how many last words have come
  std::vector<std::uint64_t> heard_;
  int last_words_ = 0;
  void test_failure(const std::string& point);
};

/// True when this process was started by Open MPI's mpirun (its environment says so).
bool launched_by_mpirun();

/// The MPI library's version line (for --version).
std::string mpi_version();

}  // namespace groundplan::cli
