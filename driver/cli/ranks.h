// SPDX-License-Identifier: MIT
#pragma once
// The ranks of a run: under `mpirun -np N` (an MPI build) the MPI exchange of the tiled run (mpi_exchange.h),
// otherwise none (nullptr everywhere).
#ifdef GROUNDPLAN_WITH_MPI
#include "mpi_exchange.h"
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

}  // namespace groundplan::cli
