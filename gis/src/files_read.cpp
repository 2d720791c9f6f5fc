// SPDX-License-Identifier: MIT
#include "files_read.h"

namespace groundplan::gis {
namespace {
thread_local std::vector<std::string>* t_heard = nullptr;
}  // namespace

void note_file_opened(const std::string& path) {
  if (t_heard && !path.empty()) t_heard->push_back(path);
}

FilesHeard::FilesHeard(std::vector<std::string>& into) : previous_(t_heard) { t_heard = &into; }
FilesHeard::~FilesHeard() { t_heard = previous_; }

}  // namespace groundplan::gis
