// SPDX-License-Identifier: MIT
// Replays tests/corpus/fuzz-regressions/<target>/* through the fuzz target bodies (issue 8): every
// input that once crashed or failed a check must now pass (no crash, no sanitizer report in the
// sanitizer build, no check failure).
#include "fuzz_entry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

int groundplan_fuzz_citygml(const std::uint8_t*, std::size_t);
int groundplan_fuzz_srs_name(const std::uint8_t*, std::size_t);
int groundplan_fuzz_coordinates(const std::uint8_t*, std::size_t);
int groundplan_fuzz_union(const std::uint8_t*, std::size_t);
int groundplan_fuzz_read_any(const std::uint8_t*, std::size_t);
int groundplan_fuzz_lod(const std::uint8_t*, std::size_t);

namespace {

namespace fs = std::filesystem;

std::size_t replay(const std::string& target, int (*body)(const std::uint8_t*, std::size_t)) {
  const fs::path dir = fs::path(GROUNDPLAN_FUZZ_REGRESSIONS_DIR) / target;
  std::size_t n = 0;
  if (!fs::is_directory(dir)) return n;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename() == "README.md") continue;
    std::ifstream f(e.path(), std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(e.path().string());
    EXPECT_NO_THROW(body(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
    ++n;
  }
  return n;
}

TEST(FuzzRegressions, CityGml) { replay("citygml", groundplan_fuzz_citygml); }
TEST(FuzzRegressions, SrsName) { replay("srs_name", groundplan_fuzz_srs_name); }
TEST(FuzzRegressions, Coordinates) { replay("coordinates", groundplan_fuzz_coordinates); }
TEST(FuzzRegressions, Union) { replay("union", groundplan_fuzz_union); }
TEST(FuzzRegressions, ReadAny) { replay("read_any", groundplan_fuzz_read_any); }
TEST(FuzzRegressions, Lod) { replay("lod", groundplan_fuzz_lod); }

/// The bodies also take the empty input and a few bytes (the smallest cases libFuzzer starts with).
TEST(FuzzRegressions, TinyInputs) {
  const std::uint8_t bytes[] = {0, 1, 2, 3, 0xff, '<', 'a', '>'};
  for (auto body : {groundplan_fuzz_citygml, groundplan_fuzz_srs_name, groundplan_fuzz_coordinates,
                    groundplan_fuzz_union, groundplan_fuzz_read_any, groundplan_fuzz_lod})
    for (std::size_t n = 0; n <= sizeof bytes; ++n) EXPECT_NO_THROW(body(bytes, n));
}

}  // namespace
