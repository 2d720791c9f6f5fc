// SPDX-License-Identifier: MIT
#include "mpi_exchange.h"

#include <groundplan/error.h>

#include <mpi.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include <unistd.h>

namespace groundplan::cli {
namespace {

constexpr int kTag = 15;
constexpr int kProgressTag = 16;  // tell_progress words: {bytes read, last}
constexpr std::uint64_t kChunk = std::uint64_t{1} << 30;  // MPI counts are int: large messages go in pieces

void check(int rc, const char* what) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int n = 0;
  MPI_Error_string(rc, text, &n);
  throw Error(std::string("MPI ") + what + " failed: " + std::string(text, static_cast<std::size_t>(n)));
}

}  // namespace

bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr;
}

std::string mpi_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int n = 0;
  MPI_Get_library_version(text, &n);
  std::string s(text, static_cast<std::size_t>(n));
  return s.substr(0, s.find_first_of(",\n"));
}

MpiExchange::MpiExchange(int* argc, char*** argv) {
  check(MPI_Init(argc, argv), "MPI_Init");
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
  check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
  MPI_Comm host = MPI_COMM_NULL;
  check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &host), "MPI_Comm_split_type");
  check(MPI_Comm_size(host, &host_ranks_), "MPI_Comm_size");
  MPI_Comm_free(&host);
}

MpiExchange::~MpiExchange() { MPI_Finalize(); }

void MpiExchange::barrier() {
  test_failure("end");
  check(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
}

std::string MpiExchange::broadcast(const std::string& text) {
  if (text.size() > static_cast<std::size_t>(1) << 30) throw Error("MPI broadcast: over 1 GiB");
  int n = static_cast<int>(text.size());
  check(MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD), "MPI_Bcast");
  std::string out = rank_ == 0 ? text : std::string(static_cast<std::size_t>(n), '\0');
  check(MPI_Bcast(out.data(), n, MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
  return out;
}

std::vector<int> MpiExchange::every_rank(int mine) {
  std::vector<int> all(static_cast<std::size_t>(size_));
  check(MPI_Allgather(&mine, 1, MPI_INT, all.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
  return all;
}

void MpiExchange::abort(const std::string& why, int code) {
  std::fprintf(stderr, "groundplan: rank %d of %d: %s; aborting every rank of the run (nothing is written)\n", rank_,
               size_, why.c_str());
  std::fflush(stderr);
  MPI_Abort(MPI_COMM_WORLD, code);
  std::_Exit(code);
}

// A test hook (tests/e2e/test_mpi.py, test_postgis.py): GROUNDPLAN_MPI_TEST_FAIL=RANK:HOW makes rank RANK fail at
// its second allgather (after the map), with HOW ending in "@end" at the final barrier (rank 0 has written then),
// with "@commit" where a rank writing into a database has written its rows but not committed them, with "@slice"
// where a rank has written its GeoPackage slice (test_point): HOW = throw (an exception, as a failing rank) or kill
// (SIGKILL, as a dead one). HOW = pretend is no failure: test_pretends(POINT) is true on that rank.
void MpiExchange::test_failure(const std::string& point) {
  if (point.empty() && ++calls_ != 2) return;
  const char* v = std::getenv("GROUNDPLAN_MPI_TEST_FAIL");
  if (!v) return;
  std::string s(v);
  const std::size_t at = s.find('@');
  const std::string where = at == std::string::npos ? std::string() : s.substr(at + 1);
  if (where != point) return;
  s.resize(std::min(s.size(), at));
  const std::size_t colon = s.find(':');
  if (colon == std::string::npos || std::atoi(s.substr(0, colon).c_str()) != rank_) return;
  if (s.substr(colon + 1) == "kill") ::raise(SIGKILL);
  throw Error("GROUNDPLAN_MPI_TEST_FAIL: rank " + std::to_string(rank_) + " fails on purpose");
}

void MpiExchange::test_point(const std::string& point) { test_failure(point); }

bool MpiExchange::test_pretends(const std::string& point) const {
  const char* v = std::getenv("GROUNDPLAN_MPI_TEST_FAIL");
  if (!v) return false;
  const std::string s(v);
  const std::size_t colon = s.find(':');
  return colon != std::string::npos && std::atoi(s.substr(0, colon).c_str()) == rank_ &&
         s.substr(colon + 1) == "pretend@" + point;
}

std::vector<char> MpiExchange::allgather(const std::vector<char>& mine, std::vector<std::uint64_t>* sizes) {
  test_failure("");
  if (mine.size() > static_cast<std::size_t>(1) << 30) throw Error("MPI allgather: a part over 1 GiB");
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(size_));
  check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
  std::vector<int> displs(counts.size(), 0);
  std::int64_t total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    if (total > INT32_MAX - counts[r]) throw Error("MPI allgather: over 2 GiB in all");
    displs[r] = static_cast<int>(total);
    total += counts[r];
  }
  std::vector<char> all(static_cast<std::size_t>(total));
  check(MPI_Allgatherv(mine.data(), n, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, MPI_COMM_WORLD),
        "MPI_Allgatherv");
  if (sizes) sizes->assign(counts.begin(), counts.end());
  return all;
}

void MpiExchange::send(int to, const std::vector<char>& bytes) {
  const std::uint64_t n = bytes.size();
  check(MPI_Send(&n, 1, MPI_UINT64_T, to, kTag, MPI_COMM_WORLD), "MPI_Send");
  for (std::uint64_t at = 0; at < n; at += kChunk) {
    const int part = static_cast<int>(std::min(kChunk, n - at));
    check(MPI_Send(bytes.data() + at, part, MPI_BYTE, to, kTag, MPI_COMM_WORLD), "MPI_Send");
  }
}

std::vector<char> MpiExchange::receive(int from) {
  std::uint64_t n = 0;
  check(MPI_Recv(&n, 1, MPI_UINT64_T, from, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
  std::vector<char> bytes(static_cast<std::size_t>(n));
  for (std::uint64_t at = 0; at < n; at += kChunk) {
    const int part = static_cast<int>(std::min(kChunk, n - at));
    check(MPI_Recv(bytes.data() + at, part, MPI_BYTE, from, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
  }
  return bytes;
}

void MpiExchange::tell_progress(std::uint64_t bytes_read, bool last) {
  if (rank_ == 0) return;
  // Words already delivered free their buffers; a rank sends one a run of tiles, so few are ever in flight.
  while (!told_.empty()) {
    int done = 0;
    check(MPI_Test(&told_.front().second, &done, MPI_STATUS_IGNORE), "MPI_Test");
    if (!done) break;
    told_.pop_front();
  }
  told_.emplace_back(std::array<std::uint64_t, 2>{bytes_read, last ? 1u : 0u}, MPI_REQUEST_NULL);
  auto& [word, request] = told_.back();
  check(MPI_Isend(word.data(), 2, MPI_UINT64_T, 0, kProgressTag, MPI_COMM_WORLD, &request), "MPI_Isend");
  if (!last) return;
  // The last word: rank 0 waits for it before the run's next collective, so this does not wait long.
  for (auto& [w, r] : told_) check(MPI_Wait(&r, MPI_STATUS_IGNORE), "MPI_Wait");
  told_.clear();
}

void MpiExchange::heard_progress(bool until_last, const std::function<void(std::uint64_t)>& more) {
  if (rank_ != 0 || size_ < 2) return;
  heard_.resize(static_cast<std::size_t>(size_), 0);
  for (;;) {
    int waiting = 0;
    MPI_Status status;
    if (until_last && last_words_ < size_ - 1) {
      check(MPI_Probe(MPI_ANY_SOURCE, kProgressTag, MPI_COMM_WORLD, &status), "MPI_Probe");
      waiting = 1;
    } else {
      check(MPI_Iprobe(MPI_ANY_SOURCE, kProgressTag, MPI_COMM_WORLD, &waiting, &status), "MPI_Iprobe");
    }
    if (!waiting) return;
    std::array<std::uint64_t, 2> word{};
    check(MPI_Recv(word.data(), 2, MPI_UINT64_T, status.MPI_SOURCE, kProgressTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
          "MPI_Recv");
    std::uint64_t& was = heard_[static_cast<std::size_t>(status.MPI_SOURCE)];
    if (word[1]) ++last_words_;
    if (word[0] > was) {
      const std::uint64_t n = word[0] - was;
      was = word[0];
      more(n);
    }
  }
}

}  // namespace groundplan::cli
