// SPDX-License-Identifier: MIT
#pragma once
// One body per fuzz target, two ways in (issue 8): as a libFuzzer target (GROUNDPLAN_FUZZ build,
// clang -fsanitize=fuzzer) the body is LLVMFuzzerTestOneInput; in the ordinary test build
// (GROUNDPLAN_FUZZ_REPLAY) it is groundplan_fuzz_<name>, which replay_test.cpp calls on every file
// of tests/corpus/fuzz-regressions/<name>/, so that a crash once found stays fixed in every CI run.
#include <cstddef>
#include <cstdint>

#ifdef GROUNDPLAN_FUZZ_REPLAY
#define GROUNDPLAN_FUZZ_TARGET(name) int groundplan_fuzz_##name(const std::uint8_t* data, std::size_t size)
#else
#define GROUNDPLAN_FUZZ_TARGET(name) extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
#endif

/// A finding the sanitizers cannot see (a wrong answer): print it and abort, so libFuzzer keeps the input.
[[noreturn]] void groundplan_fuzz_fail(const char* target, const char* what);
