// SPDX-License-Identifier: MIT
#include "real_samples.h"

#include "test_config.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <set>

namespace groundplan::test {
namespace fs = std::filesystem;

namespace {

fs::path thirdparty_root() {
  const char* env = std::getenv("GROUNDPLAN_SHARED_DATA_DIR");
  return fs::path(env != nullptr && *env != '\0' ? env : GROUNDPLAN_SHARED_DATA_DIR);
}

void collect(const fs::path& root, const std::vector<std::string>& extensions, const std::set<fs::path>& skip,
             std::set<fs::path>& seen, std::vector<std::string>& out) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return;
  for (const auto& e : fs::recursive_directory_iterator(root, fs::directory_options::follow_directory_symlink, ec)) {
    if (!e.is_regular_file()) continue;
    if (std::find(extensions.begin(), extensions.end(), e.path().extension().string()) == extensions.end()) continue;
    if (skip.count(fs::relative(e.path(), root)) != 0) continue;
    if (seen.insert(fs::canonical(e.path())).second) out.push_back(e.path().string());
  }
}

}  // namespace

std::string sample_data(const std::string& relative) { return std::string(GROUNDPLAN_SAMPLE_DATA_DIR) + "/" + relative; }

std::string thirdparty_data(const std::string& relative) { return (thirdparty_root() / relative).string(); }

std::string shared_data(const std::string& relative) {
  const fs::path in_repo = fs::path(GROUNDPLAN_REPO_DATA_DIR) / relative;
  std::error_code ec;
  return fs::exists(in_repo, ec) ? in_repo.string() : thirdparty_data(relative);
}

std::string missing_data(const std::string& path) {
  std::error_code ec;
  if (fs::exists(path, ec)) return "";
  return "needs third-party sample " + path +
         " (not redistributable, not in the repository; set GROUNDPLAN_SHARED_DATA_DIR to a copy of the samples)";
}

std::string missing_samples(Samples which) {
  if (which == Samples::InRepo) return "";
  std::error_code ec;
  if (fs::is_directory(thirdparty_root(), ec)) return "";
  return "needs the third-party samples folder " + thirdparty_root().string() +
         " (not redistributable, not in the repository; set GROUNDPLAN_SHARED_DATA_DIR to a copy of the samples)";
}

void PrintTo(Samples which, std::ostream* os) { *os << (which == Samples::InRepo ? "InRepo" : "ThirdParty"); }

std::vector<std::string> real_sample_files(Samples which, const std::vector<std::string>& extensions) {
  std::vector<std::string> out;
  std::set<fs::path> seen;
  if (which == Samples::InRepo) {
    collect(GROUNDPLAN_SAMPLE_DATA_DIR, extensions, {}, seen, out);
    collect(GROUNDPLAN_REPO_DATA_DIR, extensions, {}, seen, out);
  } else {
    std::set<fs::path> in_repo;  // the third-party folder's files that tests/data/ holds, by the same relative path
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(GROUNDPLAN_REPO_DATA_DIR, ec))
      if (!e.is_directory()) in_repo.insert(fs::relative(e.path(), GROUNDPLAN_REPO_DATA_DIR));
    collect(thirdparty_root(), extensions, in_repo, seen, out);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace groundplan::test
