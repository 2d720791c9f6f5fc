// SPDX-License-Identifier: MIT
#include "fuzz_entry.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

void groundplan_fuzz_fail(const char* target, const char* what) {
#ifdef GROUNDPLAN_FUZZ_REPLAY
  throw std::runtime_error(std::string(target) + ": " + what);
#else
  std::fprintf(stderr, "groundplan fuzz %s: %s\n", target, what);
  std::abort();
#endif
}
