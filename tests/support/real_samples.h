// SPDX-License-Identifier: MIT
#pragma once
// Where the C++ tests find real city models. Three roots:
//  - sample_data/          the bundled samples (README's quick start);
//  - tests/data/           the redistributable third-party samples, one folder per dataset, named as in
//                          ../shared/data (each with its SOURCE.txt: origin, licence);
//  - the third-party folder: samples that may not be redistributed. $GROUNDPLAN_SHARED_DATA_DIR when set, else
//                          ../shared/data beside the source tree when it existed at configure time. It may be absent
//                          (a clean clone): tests that need it are named *ThirdParty* (ctest label thirdparty-data)
//                          and skip with one line naming what is missing.
#include <ostream>
#include <string>
#include <vector>

namespace groundplan::test {

/// Path of a file under sample_data/.
std::string sample_data(const std::string& relative);
/// Path of a real sample named as in ../shared/data ("folder/file"): its copy in tests/data/ when the repository has
/// it, else its path under the third-party folder (which may be missing: use GROUNDPLAN_SKIP_IF_MISSING there).
std::string shared_data(const std::string& relative);
/// Path under the third-party folder, for a dataset's folder that tests/data/ holds only in part.
std::string thirdparty_data(const std::string& relative);
/// "" when `path` exists, else the one line a test skips with (what is missing and where it was looked for).
std::string missing_data(const std::string& path);

enum class Samples {
  InRepo,      ///< sample_data/ and tests/data/
  ThirdParty,  ///< the third-party folder, less what tests/data/ holds too (empty when the folder is absent)
};
/// Every regular file of those roots whose extension is one of `extensions` (".gml", ...), each file once
/// (links followed), sorted.
std::vector<std::string> real_sample_files(Samples which, const std::vector<std::string>& extensions);
/// "" when the roots of `which` exist, else the one line a test skips with (the third-party folder is absent).
std::string missing_samples(Samples which);
/// gtest's name for the parameter of suites instantiated once per Samples value ("InRepo", "ThirdParty").
void PrintTo(Samples which, std::ostream* os);

}  // namespace groundplan::test

/// Skips the current test (one line) when `path` does not exist (in a gtest test body; include gtest first).
#define GROUNDPLAN_SKIP_IF_MISSING(path)                                              \
  do {                                                                                 \
    const std::string groundplan_missing_ = ::groundplan::test::missing_data(path);  \
    if (!groundplan_missing_.empty()) GTEST_SKIP() << groundplan_missing_;            \
  } while (0)

/// Skips the current test (one line) when the roots of `which` (a test::Samples) are absent.
#define GROUNDPLAN_SKIP_IF_NO_SAMPLES(which)                                              \
  do {                                                                                     \
    const std::string groundplan_missing_ = ::groundplan::test::missing_samples(which);  \
    if (!groundplan_missing_.empty()) GTEST_SKIP() << groundplan_missing_;                \
  } while (0)
