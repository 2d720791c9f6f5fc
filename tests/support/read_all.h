// SPDX-License-Identifier: MIT
#pragma once
// For the reader tests (they link groundplan_gis; the support library does not): every mesh and
// problem of one read_any call.
#include <groundplan/gis/reader.h>
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <string>
#include <vector>

namespace groundplan::test {

struct Read {
  std::vector<Mesh> meshes;
  std::vector<Problem> problems;
  gis::ReadInfo info;
  std::size_t count(const std::string& code) const {
    std::size_t n = 0;
    for (const Problem& p : problems) n += p.code == code;
    return n;
  }
  std::string all() const {
    std::string s;
    for (const Problem& p : problems) s += p.code + ": " + p.reason + "\n";
    return s;
  }
};

inline Read read(const std::string& path, const gis::ReadOptions& opt = {}) {
  Read r;
  gis::read_any(path, opt, [&](Mesh&& m) { r.meshes.push_back(std::move(m)); }, r.problems, r.info);
  return r;
}

}  // namespace groundplan::test
