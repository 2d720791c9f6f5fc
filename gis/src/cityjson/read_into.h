// SPDX-License-Identifier: MIT
#pragma once
// read_any's CityJSON branch (issue 16): the options and the ReadInfo fields read_any speaks in.
#include <groundplan/gis/reader.h>

namespace groundplan::gis::cityjson {

/// Reads info.format (CityJson or CityJsonSeq) and fills info.cityjson, and info.citygml's srs_name and
/// envelope, so that the pipeline builds the working frame of a CityJSON file as it does for CityGML.
void read_into(const std::string& path, const ReadOptions& options, std::uint64_t max_bytes, const MeshCallback& on_mesh,
               std::vector<Problem>& problems, ReadInfo& info);

}  // namespace groundplan::gis::cityjson
