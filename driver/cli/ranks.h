// SPDX-License-Identifier: MIT
#pragma once
// The ranks of a run: under `mpirun -np N` (an MPI build) the MPI exchange of the tiled run (mpi_exchange.h),
// otherwise none (nullptr everywhere).
#ifdef GROUNDPLAN_WITH_MPI
#include "mpi_exchange.h"

#include <groundplan/gis/pipeline.h>

#include <algorithm>
#include <thread>
#endif

namespace groundplan::cli {

#ifdef GROUNDPLAN_WITH_MPI
using Ranks = MpiExchange;
#else
/// Without MPI there is one rank and no exchange (nullptr everywhere).
class Ranks {};
#endif

/// Ranks of the run: more than one only under `mpirun -np N` with N > 1 (an MPI build).
inline int rank_count(Ranks* ranks) {
#ifdef GROUNDPLAN_WITH_MPI
  return ranks ? ranks->size() : 1;
#else
  (void)ranks;
  return 1;
#endif
}

/// Threads of a rank without --threads or GDAL_NUM_THREADS (0: all cores): under mpirun, the cores this rank may
/// use shared with the job's other ranks on its host, so that N ranks on one host do not start N x cores threads (16
/// ranks x 2 threads on 32 cores: 3.7 s where 16 x 1 took 4.7, tests/bench/RESULTS.md). A rank the launcher bound to
/// fewer cores than the host has (--bind-to core, --map-by ...:pe=n) takes those.
inline int default_threads(Ranks* ranks) {
#ifdef GROUNDPLAN_WITH_MPI
  if (rank_count(ranks) > 1) {
    const int usable = static_cast<int>(groundplan::gis::thread_count(0));  // the affinity mask's cores
    const int host = static_cast<int>(std::thread::hardware_concurrency());
    return usable < host ? usable : std::max(1, usable / ranks->ranks_on_host());
  }
#else
  (void)ranks;
#endif
  return 0;
}

}  // namespace groundplan::cli
