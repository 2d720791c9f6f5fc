// SPDX-License-Identifier: MIT
#include "staged_output.h"

#include <groundplan/error.h>

#include <filesystem>
#include <system_error>

#include <unistd.h>

namespace groundplan::output {

namespace fs = std::filesystem;

StagedOutput::StagedOutput(const std::string& dst) : dst_(dst), path_(dst) {
  std::error_code ec;
  if (dst.empty() || dst.rfind("/vsi", 0) == 0 || dst.find(':') != std::string::npos || fs::exists(dst, ec)) return;
  const fs::path p(dst);
  parent_ = p.has_parent_path() ? p.parent_path().string() : ".";
  const fs::path stage = fs::path(parent_) / (".groundplan-partial-" + std::to_string(::getpid()));
  if (!fs::create_directory(stage, ec) || ec) {
    parent_.clear();
    return;  // cannot stage (read-only folder ...): written in place, as before
  }
  stage_ = stage.string();
  path_ = (stage / p.filename()).string();
}

StagedOutput::~StagedOutput() {
  if (stage_.empty()) return;
  std::error_code ec;
  fs::remove_all(stage_, ec);
}

void StagedOutput::commit() {
  if (stage_.empty()) return;
  for (const fs::directory_entry& e : fs::directory_iterator(stage_)) {
    const fs::path to = fs::path(parent_) / e.path().filename();
    std::error_code ec;
    fs::rename(e.path(), to, ec);
    if (ec) throw Error("cannot move " + e.path().string() + " to " + to.string() + ": " + ec.message());
  }
  std::error_code ec;
  fs::remove(stage_, ec);
  stage_.clear();
}

}  // namespace groundplan::output
