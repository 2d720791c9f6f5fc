// SPDX-License-Identifier: MIT
#include "ogr2ogr_args.h"

#include <groundplan/error.h>

#include <gdal_version.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <set>

namespace groundplan::cli {
namespace {

/// ogr2ogr options that take values (GDAL 3.6 ogr2ogr_lib.cpp), so that the positional arguments
/// (destination, source, layer names) can be told apart from option values.
int ogr2ogr_arity(const std::string& opt, const std::vector<std::string>& args, std::size_t i) {
  static const std::set<std::string> one = {
      "-f", "-of", "-dsco", "-lco", "-nln", "-nlt", "-t_srs", "-s_srs", "-a_srs", "-where", "-sql", "-dialect",
      "-spat_srs", "-fid", "-select", "-geomfield", "-gt", "-simplify", "-segmentize", "-fieldTypeToString",
      "-mapFieldType", "-fieldmap", "-zfield", "-oo", "-doo", "-mo", "-ct", "-clipsrcsql", "-clipsrclayer",
      "-clipsrcwhere", "-clipdstsql", "-clipdstlayer", "-clipdstwhere", "-datelineoffset", "-limit", "-order",
      "-a_coord_epoch", "-s_coord_epoch", "-t_coord_epoch", "-xyRes", "-zRes", "-mRes", "-dim", "-maxsubfields",
      "-if", "--config", "--debug", "--optfile"};
  if (opt == "-spat") return 4;
  if (opt == "--config") return 2;
  if (opt == "-gcp") {
    // 4 numbers, and an optional fifth (elevation).
    int n = 4;
    if (i + 5 < args.size()) {
      char* end = nullptr;
      std::strtod(args[i + 5].c_str(), &end);
      if (end && *end == '\0' && !args[i + 5].empty()) n = 5;
    }
    return n;
  }
  if (opt == "-clipsrc" || opt == "-clipdst") {
    // Either one value (WKT, datasource, spat_extent) or xmin ymin xmax ymax.
    if (i + 1 < args.size()) {
      char* end = nullptr;
      std::strtod(args[i + 1].c_str(), &end);
      if (end && *end == '\0' && !args[i + 1].empty()) return 4;
    }
    return 1;
  }
  return one.count(opt) ? 1 : 0;
}

}  // namespace

Ogr2ogrArgs split_ogr2ogr_args(const std::vector<std::string>& args) {
  Ogr2ogrArgs out;
  std::vector<std::string> positional;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() > 1 && a[0] == '-') {
      const int n = ogr2ogr_arity(a, args, i);
      if (i + static_cast<std::size_t>(n) >= args.size())
        throw groundplan::InvalidArgument("option " + a + " needs " + std::to_string(n) + " value(s)");
      if (a == "-progress") out.progress = true;
      if (a == "-q" || a == "-quiet") out.quiet = true;
      if (a == "-f" || a == "-of") out.format = args[i + 1];
      out.options.push_back(a);
      for (int k = 1; k <= n; ++k) out.options.push_back(args[i + static_cast<std::size_t>(k)]);
      i += static_cast<std::size_t>(n);
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() < 2)
    throw groundplan::InvalidArgument(
        "expected a destination and a source: groundplan [options] dst_datasource src_file [layer ...]");
  out.dst = positional[0];
  out.src = positional[1];
  for (std::size_t i = 2; i < positional.size(); ++i) {
    out.options.push_back(positional[i]);  // layer names, as ogr2ogr takes them
    out.layers.push_back(positional[i]);
    out.layer_named = true;
  }
  return out;
}

std::string take_source_srs(std::vector<std::string>& options) {
  std::string srs;
  for (std::size_t i = 0; i + 1 < options.size();) {
    if (options[i] == "-s_srs" || options[i] == "-a_srs") {
      srs = options[i + 1];
      options.erase(options.begin() + static_cast<std::ptrdiff_t>(i), options.begin() + static_cast<std::ptrdiff_t>(i) + 2);
    } else {
      ++i;
    }
  }
  return srs;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool writes_dbf(const Ogr2ogrArgs& ogr) {
  if (!ogr.format.empty()) return lower(ogr.format) == "esri shapefile";
  const std::string ext = lower(std::filesystem::path(ogr.dst).extension().string());
  return ext == ".shp" || ext == ".dbf";
}

bool packs_gpkg_index(const Ogr2ogrArgs& ogr) {
  if (GDAL_VERSION_NUM >= 3070000) return false;
  const std::string ext = lower(std::filesystem::path(ogr.dst).extension().string());
  if (!(ogr.format.empty() ? ext == ".gpkg" : lower(ogr.format) == "gpkg")) return false;
  std::error_code ec;
  if (ogr.dst.rfind("/vsi", 0) == 0 || std::filesystem::exists(ogr.dst, ec)) return false;
  for (std::size_t i = 0; i < ogr.options.size(); ++i) {
    const std::string o = lower(ogr.options[i]);
    if (o == "-append" || o == "-update" || o == "-upsert" || o == "-addfields") return false;
    if (o == "-lco" && i + 1 < ogr.options.size() && lower(ogr.options[i + 1]).rfind("spatial_index=", 0) == 0)
      return false;
  }
  return true;
}

std::vector<std::string> option_flags(const Ogr2ogrArgs& ogr) {
  return {ogr.options.begin(), ogr.options.end() - static_cast<std::ptrdiff_t>(ogr.layers.size())};
}
std::vector<std::string> written_layers(const Ogr2ogrArgs& ogr) {
  return ogr.layer_named ? ogr.layers : std::vector<std::string>{"ground_plans"};
}

}  // namespace groundplan::cli
