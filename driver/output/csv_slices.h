// SPDX-License-Identifier: MIT
#pragma once
// A new CSV file of the plans written by several GDAL writers at once (issue 14), as a new GeoPackage is
// (gpkg_slices.h): GDAL's CSV writer is one thread, and turning every plan into WKT made it the longest stage of
// a city run with `-f CSV -lco GEOMETRY=AS_WKT` (121,856 plans: 3.4-6 s of a 5-8 s run on 16 cores,
// tests/bench/RESULTS.md). Slice k of the plans goes to a file of its own beside the destination, slice 0 straight
// into it; then the other slices' lines, past their header line, are appended in slice order. A CSV file is its
// header and its rows, one line each (the plans' fields hold no line breaks, and GDAL quotes a field that would),
// so the file is byte for byte what one writer makes. Only the options known to keep that hold are sliced.
#include "gpkg_slices.h"

#include <string>
#include <vector>

namespace groundplan::output {

/// True when `dst` with `format` (ogr2ogr's -f, empty: from the name) is one CSV file: the CSV driver, a name
/// ending in .csv, not under /vsi.
bool is_csv_file(const std::string& format, const std::string& dst);

/// How many writers a new CSV file of the plans gets; 1 (and `why_one`) when one writer writes it: few plans or
/// threads, a layer besides the plans, an option whose effect spans features, or a creation option other than
/// GEOMETRY, SEPARATOR, LINEFORMAT, STRING_QUOTING (-lco HEADERS, WRITE_BOM, CREATE_CSVT ... write files or lines
/// once).
int csv_writers(const std::vector<std::string>& flags, const std::vector<std::string>& layers,
                const std::string& plans_layer, std::size_t plans, int threads, std::string* why_one);

/// Writes `w.dst` (a CSV file that does not exist yet) with `w.writers` writers side by side. On failure nothing
/// is left under `w.dst` nor beside it.
SliceOutcome write_csv_slices(const SliceWrite& w, const SliceSource& source, const Translate& translate);

}  // namespace groundplan::output
