// SPDX-License-Identifier: MIT
// Cutting a CityGML file at its members, and telling whether the chunks read it as the whole-file
// reader does (citygml_chunks.h says why a cut is safe).
#include <groundplan/error.h>
#include <groundplan/gis/citygml_chunks.h>
#include <groundplan/gis/reader.h>

#include "citygml/file_problems.h"

#include <cpl_vsi.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cstring>
#include <string_view>
#include <utility>
#include <vector>

namespace groundplan::gis {
namespace {

constexpr std::uint64_t kWindow = 64u << 10;        // bytes read at a time around a cut
constexpr std::uint64_t kFirstHead = 64u << 10;     // the head is read in reads doubling from this
constexpr std::uint64_t kMaxHead = 16u << 20;       // the first member must start within this
constexpr std::uint64_t kMaxMemberSearch = 64u << 20;  // past this without a member start, no more cuts

bool name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
         c == '.' || c == ':';
}

/// Position of the first start tag `<[prefix:]cityObjectMember` or `<[prefix:]featureMember` in `buf`
/// (followed by white space, '>' or '/'), or npos. A tag cut by the buffer's end is not found.
std::size_t find_member_start(std::string_view buf) {
  std::size_t pos = 0;
  while ((pos = buf.find('<', pos)) != std::string_view::npos) {
    std::size_t e = pos + 1;
    while (e < buf.size() && name_char(buf[e])) ++e;
    if (e >= buf.size()) return std::string_view::npos;
    const std::string_view qname = buf.substr(pos + 1, e - pos - 1);
    const std::size_t colon = qname.rfind(':');
    const std::string_view local = colon == std::string_view::npos ? qname : qname.substr(colon + 1);
    const char after = buf[e];
    if ((local == "cityObjectMember" || local == "featureMember") &&
        (after == ' ' || after == '\t' || after == '\r' || after == '\n' || after == '>' || after == '/'))
      return pos;
    pos = e;
  }
  return std::string_view::npos;
}

/// The root element's qualified name, from the bytes before the first member; empty when something
/// other than the XML declaration, comments and processing instructions comes before it.
std::string root_name(std::string_view head, std::string& why) {
  std::size_t pos = 0;
  for (;;) {
    pos = head.find('<', pos);
    if (pos == std::string_view::npos || pos + 1 >= head.size()) {
      why = "no root element before the first member";
      return {};
    }
    if (head[pos + 1] == '?') {
      pos = head.find("?>", pos);
    } else if (head.compare(pos, 4, "<!--") == 0) {
      pos = head.find("-->", pos);
    } else if (head[pos + 1] == '!') {
      why = "a DOCTYPE declaration";
      return {};
    } else {
      std::size_t e = pos + 1;
      while (e < head.size() && name_char(head[e])) ++e;
      if (e == pos + 1) {
        why = "no root element before the first member";
        return {};
      }
      return std::string(head.substr(pos + 1, e - pos - 1));
    }
    if (pos == std::string_view::npos) {
      why = "an unterminated declaration before the root element";
      return {};
    }
  }
}

struct VsiFile {
  VSILFILE* f = nullptr;
  ~VsiFile() {
    if (f) VSIFCloseL(f);
  }
  /// Up to `n` bytes at `at`, into one buffer reused from read to read (planning a file of many cuts
  /// reads a few KiB per cut, not a fresh zero-filled buffer each time).
  std::string_view read(std::uint64_t at, std::uint64_t n) {
    if (buf_.size() < n) buf_.resize(static_cast<std::size_t>(n));
    if (VSIFSeekL(f, at, SEEK_SET) != 0) return {};
    return {buf_.data(), VSIFReadL(buf_.data(), 1, static_cast<std::size_t>(n), f)};
  }

 private:
  std::string buf_;
};

/// The first member start at or after `from`, or `size` when there is none within kMaxMemberSearch.
std::uint64_t next_member_start(VsiFile& file, std::uint64_t from, std::uint64_t size) {
  constexpr std::uint64_t kOverlap = 256;  // a tag cut by a window's end is found in the next window
  for (std::uint64_t at = from; at < size && at - from < kMaxMemberSearch; at += kWindow) {
    const std::string_view buf = file.read(at, std::min(kWindow + kOverlap, size - at));
    const std::size_t p = find_member_start(buf);
    if (p != std::string_view::npos) return at + p;
    if (buf.size() <= kOverlap) break;
  }
  return size;
}

}  // namespace

CityGmlChunkPlan plan_citygml_chunks(const std::string& path, std::uint64_t chunk_bytes,
                                     std::uint64_t first_chunk_bytes) {
  CityGmlChunkPlan plan;
  if ((path.rfind("/vsi", 0) == 0 && path.rfind("/vsimem/", 0) != 0) || is_gzip_input_name(path)) {
    plan.why_not = "compressed or virtual input (read as one stream)";
    return plan;
  }
  VSIStatBufL st;
  if (VSIStatL(path.c_str(), &st) != 0) throw InputError(path + ": cannot open the file (does it exist and is it readable?)");
  plan.file_bytes = static_cast<std::uint64_t>(st.st_size);
  VsiFile file;
  file.f = VSIFOpenL(path.c_str(), "rb");
  if (!file.f) throw InputError(path + ": cannot open the file (does it exist and is it readable?)");

  // The head, in reads doubling in size: a file's first member usually starts within a few KiB.
  std::string_view head;
  std::size_t first = std::string_view::npos;
  for (std::uint64_t n = std::min(kFirstHead, plan.file_bytes);; n = std::min(2 * n, std::min(kMaxHead, plan.file_bytes))) {
    head = file.read(0, n);
    first = find_member_start(head);
    if (first != std::string_view::npos || n >= std::min(kMaxHead, plan.file_bytes)) break;
  }
  if (first == std::string_view::npos) {
    plan.why_not = "no cityObjectMember or featureMember in the first 16 MiB";
    return plan;
  }
  const std::string root = root_name(head.substr(0, first), plan.why_not);
  if (root.empty()) return plan;
  plan.head = std::string(head.substr(0, first));
  plan.tail = "</" + root + ">";

  std::uint64_t begin = first;
  std::uint64_t target = first + std::max<std::uint64_t>(1, first_chunk_bytes);
  while (target < plan.file_bytes) {
    const std::uint64_t cut = next_member_start(file, target, plan.file_bytes);
    if (cut >= plan.file_bytes) break;
    plan.ranges.emplace_back(begin, cut);
    begin = cut;
    target = cut + std::max<std::uint64_t>(1, chunk_bytes);
  }
  plan.ranges.emplace_back(begin, plan.file_bytes);
  if (plan.ranges.size() < 2) {
    plan.ranges.clear();
    plan.why_not = "one chunk only";
  }
  return plan;
}

std::string merge_citygml_chunks(const std::string& path, const CityGmlChunkPlan& plan,
                                 const std::vector<SourceInfo>& infos, const std::vector<CityGmlChunkWatch>& watches,
                                 SourceInfo& merged, std::vector<Problem>& file_problems) {
  merged = SourceInfo{};
  merged.file = path;
  int file_dimension = 0;  // the whole-file reader's default srsDimension where the chunk starts
  for (std::size_t k = 0; k < infos.size(); ++k) {
    const SourceInfo& in = infos[k];
    const CityGmlChunkWatch& w = watches[k];
    if (w.position_dependent)
      return "a building or polygon without gml:id is named by its line (read whole to keep the names)";
    if (w.cross_building_xlink) return "xlinks between buildings (resolved by reading the file whole)";
    if (w.file_level_problem) return "a once-per-file problem (BAD_SRS_DIMENSION outside buildings)";
    if (file_dimension != 0 && (w.dimension_defaults & ~(1u << file_dimension)) != 0)
      return "coordinates without srsDimension before the file's first srsDimension";
    if (file_dimension == 0) file_dimension = in.srs_dimension;
    if (merged.citygml_version.empty()) merged.citygml_version = in.citygml_version;
    if (merged.srs_name.empty()) {
      merged.srs_name = in.srs_name;
      merged.srs_mixed = in.srs_mixed;
      merged.other_srs_name = in.other_srs_name;
    } else if (!merged.srs_mixed && !in.srs_name.empty()) {
      if (in.srs_name != merged.srs_name) {
        merged.srs_mixed = true;
        merged.other_srs_name = in.srs_name;
      } else if (in.srs_mixed) {
        merged.srs_mixed = true;
        merged.other_srs_name = in.other_srs_name;
      }
    }
    if (!merged.srs_dimension) merged.srs_dimension = in.srs_dimension;
    if (!merged.has_envelope && in.has_envelope) {
      merged.has_envelope = true;
      std::copy(in.envelope_lower, in.envelope_lower + 3, merged.envelope_lower);
      std::copy(in.envelope_upper, in.envelope_upper + 3, merged.envelope_upper);
    }
    merged.buildings += in.buildings;
    merged.building_parts += in.building_parts;
    merged.meshes += in.meshes;
    merged.buildings_dropped += in.buildings_dropped;
    merged.faces += in.faces;
    merged.xlinks_resolved += in.xlinks_resolved;
    merged.xlinks_missing += in.xlinks_missing;
    merged.bytes_streamed += in.bytes_streamed;
    if (merged.streamed_why.empty()) merged.streamed_why = in.streamed_why;
  }
  // A gml:id in two chunks: each chunk's reader saw only its own (DUPLICATE_ID is said per file).
  // Sorted on all cores: one hash set of every id would be a serial pass over the whole file's ids.
  std::vector<std::pair<std::string_view, std::size_t>> ids;
  for (std::size_t k = 0; k < watches.size(); ++k)
    for (const std::string& id : watches[k].building_ids) ids.emplace_back(id, k);
  tbb::parallel_sort(ids.begin(), ids.end());
  for (std::size_t i = 1; i < ids.size(); ++i)
    if (ids[i].first == ids[i - 1].first && ids[i].second != ids[i - 1].second)
      return "gml:id \"" + std::string(ids[i].first) + "\" is used in two chunks (DUPLICATE_ID)";
  merged.bytes = plan.file_bytes;
  detail::add_file_problems(merged, path, file_problems);
  return {};
}

}  // namespace groundplan::gis
