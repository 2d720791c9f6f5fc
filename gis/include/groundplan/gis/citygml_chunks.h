// SPDX-License-Identifier: MIT
#pragma once
// One large CityGML file read on many cores (issue 14): the file is cut into byte ranges at the start
// tags of the root's members (cityObjectMember, featureMember: CityGML 1/2/3, any prefix); each range
// is parsed as a document of its own, made of the file's head (XML declaration, root start tag with
// its namespace declarations, envelope: everything before the first member), the range, and the
// root's end tag.
//
// Why a cut is safe: if every non-last chunk parses as well-formed XML, its range ended with only the
// root open (not inside a member, a comment, CDATA or a processing instruction), so the next range
// starts where the whole-file parser is between two members too, in the same namespace context. A
// cut in a wrong place therefore makes a chunk fail, never read differently.
//
// What can still differ from the whole-file read is reader state that spans members: xlinks between
// buildings, ids made from line numbers, once-per-file problems, the file's default srsDimension, and
// duplicate ids across chunks. A chunk reader records these (CityGmlChunkWatch); merge_citygml_chunks
// then says whether the chunks are the whole file's reading, and the caller reads the file whole
// (serially) when they are not. Either way the result is the whole-file reader's, byte for byte.
#include <groundplan/gis/citygml.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace groundplan::gis {

struct CityGmlChunkPlan {
  std::string head;   // the file's bytes before the first member
  std::string tail;   // the root's end tag, closing every chunk but the last
  std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges;  // [begin, end) byte ranges, in file order
  std::uint64_t file_bytes = 0;
  std::string why_not;  // non-empty: the file is read whole, and this says why (ranges then empty)
};

/// Cuts `path` into ranges of about `chunk_bytes` (the first one `first_chunk_bytes`, so that the
/// file's first building, which may decide the working CRS, is read soon). Reads only a window around
/// each cut. Local files and /vsimem/ only: compressed and remote inputs are read whole. Never throws
/// for the file's content (why_not says what stopped it); throws InputError when it cannot be opened.
CityGmlChunkPlan plan_citygml_chunks(const std::string& path, std::uint64_t chunk_bytes,
                                     std::uint64_t first_chunk_bytes);

/// What a chunk's reader met that the whole-file reader might have read otherwise.
struct CityGmlChunkWatch {
  bool position_dependent = false;    // an id or message made from a line number or a running count
  bool cross_building_xlink = false;  // an xlink resolved through another building, or not resolved
  bool file_level_problem = false;    // a once-per-file problem (BAD_SRS_DIMENSION outside buildings)
  unsigned dimension_defaults = 0;    // bit d: a coordinate dimension inferred with the file default d
  std::vector<std::string> building_ids;  // gml:ids of its Buildings / BuildingParts (DUPLICATE_ID)
};

/// Reads chunk `k` of `plan`: meshes and per-building problems exactly as the whole-file reader gives
/// them for that range, but no file-level problem (NOT_CITYGML, MIXED_SRS: merge_citygml_chunks says
/// those). options.on_bytes hears the range's bytes only. Throws InputError when the chunk is not well-formed (then read the file whole).
void read_citygml_chunk(const std::string& path, const CityGmlChunkPlan& plan, std::size_t k,
                        const CityGmlOptions& options, const MeshCallback& on_mesh, std::vector<Problem>& problems,
                        SourceInfo& info, CityGmlChunkWatch& watch);

/// Merges the chunks' SourceInfo into the file's and appends the file-level problems the whole-file
/// reader adds at its end. Returns an empty string when the chunks read the file exactly as the
/// whole-file reader does; else the reason why not (then `merged` and `file_problems` are unspecified
/// and the file must be read whole).
std::string merge_citygml_chunks(const std::string& path, const CityGmlChunkPlan& plan,
                                 const std::vector<SourceInfo>& infos, const std::vector<CityGmlChunkWatch>& watches,
                                 SourceInfo& merged, std::vector<Problem>& file_problems);

}  // namespace groundplan::gis
