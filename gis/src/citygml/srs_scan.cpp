// SPDX-License-Identifier: MIT
#include "citygml/srs_scan.h"

#include <groundplan/gis/reader.h>

#include <cpl_vsi.h>

#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string_view>

namespace groundplan::gis::citygml {
namespace {

struct VsiClose {
  void operator()(VSILFILE* f) const { VSIFCloseL(f); }
};

/// The value of the first `srsName="..."` (or '...') in `text` from `from` on; npos-free: empty when none whole.
bool value_at(std::string_view text, std::size_t at, std::string& out) {
  std::size_t p = at + std::strlen("srsName");
  while (p < text.size() && (text[p] == ' ' || text[p] == '\t' || text[p] == '\r' || text[p] == '\n')) ++p;
  if (p >= text.size() || text[p] != '=') return false;
  ++p;
  while (p < text.size() && (text[p] == ' ' || text[p] == '\t' || text[p] == '\r' || text[p] == '\n')) ++p;
  if (p >= text.size() || (text[p] != '"' && text[p] != '\'')) return false;
  const char quote = text[p++];
  const std::size_t end = text.find(quote, p);
  if (end == std::string_view::npos || end - p > 1024) return false;
  out.assign(text.substr(p, end - p));
  return !out.empty();
}

std::string scan(const std::string& path) {
  std::unique_ptr<VSILFILE, VsiClose> f(VSIFOpenL(open_path(path).c_str(), "rb"));
  if (!f) return {};
  constexpr std::size_t kBlock = std::size_t{1} << 20, kKeep = 2048;  // an attribute spans a block's end
  std::string buf;
  std::string found;
  for (;;) {
    const std::size_t kept = buf.size();
    buf.resize(kept + kBlock);
    const std::size_t n = VSIFReadL(buf.data() + kept, 1, kBlock, f.get());
    buf.resize(kept + n);
    const std::string_view text(buf);
    for (std::size_t at = text.find("srsName"); at != std::string_view::npos; at = text.find("srsName", at + 1))
      if (value_at(text, at, found)) return found;
    if (n < kBlock) return {};
    buf.erase(0, buf.size() > kKeep ? buf.size() - kKeep : 0);
  }
}

}  // namespace

std::string first_srs_name_in(const std::string& path) {
  VSIStatBufL st;
  if (VSIStatL(open_path(path).c_str(), &st) != 0) return {};
  const std::string key = path + '\n' + std::to_string(st.st_size) + '\n' + std::to_string(st.st_mtime);
  static std::mutex mu;
  static std::map<std::string, std::string> known;
  {
    std::lock_guard<std::mutex> lock(mu);
    if (auto it = known.find(key); it != known.end()) return it->second;
  }
  std::string srs = scan(path);
  std::lock_guard<std::mutex> lock(mu);
  if (known.size() > 64) known.clear();
  known.emplace(key, srs);
  return srs;
}

}  // namespace groundplan::gis::citygml
