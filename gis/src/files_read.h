// SPDX-License-Identifier: MIT
#pragma once
// The files the readers open while one input is read: the input itself and what it links (a KML's COLLADA
// models and NetworkLinks, a glTF's buffers, an OGR source's files). Every place a reader opens a file tells
// note_file_opened(); a FilesHeard set around a reading on the same thread collects what is told (readers open
// files on the thread that reads). The driver's result cache keys on these files (PipelineResult::files_read).
#include <string>
#include <vector>

namespace groundplan::gis {

/// Tells the FilesHeard of this thread, if any, that `path` was opened.
void note_file_opened(const std::string& path);

/// Collects into `into` the files opened on this thread while it lives (nested: the innermost hears).
class FilesHeard {
 public:
  explicit FilesHeard(std::vector<std::string>& into);
  ~FilesHeard();
  FilesHeard(const FilesHeard&) = delete;
  FilesHeard& operator=(const FilesHeard&) = delete;

 private:
  std::vector<std::string>* previous_;
};

}  // namespace groundplan::gis
