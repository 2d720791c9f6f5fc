// SPDX-License-Identifier: MIT
#pragma once
// The srsName of a CityGML file whose first building comes before any srsName: the pipeline places each
// building as it is read, with the srsName known by then; a file that names its CRS only on a later envelope
// (another object's, a LandUse or Relief written after the buildings) still has one CRS for all of it.
#include <string>

namespace groundplan::gis::citygml {

/// The first srsName attribute written anywhere in the CityGML file `path` (a .gz through /vsigzip/), as
/// written; empty when there is none or the file cannot be read. A byte search, not an XML parse; remembered
/// per file (path, size, modification time), so that the chunks of one file search it once.
std::string first_srs_name_in(const std::string& path);

}  // namespace groundplan::gis::citygml
