// SPDX-License-Identifier: MIT
#include "open_options.h"

#include <groundplan/error.h>
#include <groundplan/gis/lod_choice.h>

#include <cpl_string.h>

#include <charconv>
#include <cmath>
#include <cstring>

namespace groundplan::driver {

const char* open_option_list_xml() {
  return "<OpenOptionList>"
         "  <Option name='RESOLUTION' type='float' description='Raster pixel size in metres used to find blocks and "
         "seeds (0 = automatic). The result is exact whatever the value.' default='0'/>"
         "  <Option name='DEVICE' type='string-select' description='Where blocks are rasterised (AUTO: the CPU; CUDA only when asked for)' default='AUTO'>"
         "    <Value>AUTO</Value><Value>CPU</Value><Value>CUDA</Value>"
         "  </Option>"
         "  <Option name='FOOTPRINTS' type='string-select' description='Where footprints come from: explicit ground "
         "geometry when present (AUTO), only explicit ground geometry, or surface decomposition' default='AUTO'>"
         "    <Value>AUTO</Value><Value>GROUND-SURFACE</Value><Value>DECOMPOSE</Value>"
         "  </Option>"
         "  <Option name='LOD' type='string' description='Level of detail to read: -1 (highest available per "
         "building), 0..4, or with CityJSON&apos;s refinement (1.2, 1.3, 2.2)' default='-1'/>"
         "  <Option name='T_SRS' type='string' description='Working CRS for the union (projected, metric); default: "
         "the source CRS when projected, else the UTM zone of the data'/>"
         "  <Option name='S_SRS' type='string' description='CRS of the CityGML/CityJSON coordinates, in place of "
         "the srsName / referenceSystem the files give (as ogr2ogr -s_srs)'/>"
         "  <Option name='A_SRS' type='string' description='The same as S_SRS (ogr2ogr -a_srs)'/>"
         "  <Option name='ORIGIN' type='string' description='lon,lat[,alt] (degrees, metres) where a glTF without "
         "georeference or a bare COLLADA file sits'/>"
         "  <Option name='AXIS_ORDER' type='string-select' description='CityGML axis order when a file breaks its "
         "CRS&apos;s rule (EPSG:4979 written lon,lat): AUTO follows the CRS' default='AUTO'>"
         "    <Value>AUTO</Value><Value>EAST-NORTH</Value><Value>NORTH-EAST</Value>"
         "  </Option>"
         "  <Option name='RESOLUTION_MODE' type='string-select' description='EXACT: the resolution only finds "
         "blocks. RASTER: the paper&apos;s level of detail, holes that hold no whole pixel are filled' default='EXACT'>"
         "    <Value>EXACT</Value><Value>RASTER</Value>"
         "  </Option>"
         "  <Option name='PRESET' type='string-select' description='Level-of-detail preset (CFD: snap 0.01, close "
         "gaps 0.5, simplify 0.1, min hole area 1, min area 1); options given explicitly override it' default='NONE'>"
         "    <Value>NONE</Value><Value>CFD</Value>"
         "  </Option>"
         "  <Option name='SNAP' type='float' description='Metres: vertices and edges closer than this become shared "
         "before the union (0 = off)' default='0'/>"
         "  <Option name='CLOSE_GAPS' type='float' description='Metres: gaps and cavities narrower than this close "
         "(0 = off)' default='0'/>"
         "  <Option name='MIN_HOLE_AREA' type='float' description='m2: smaller holes are filled (0 = off)' "
         "default='0'/>"
         "  <Option name='MIN_AREA' type='float' description='m2: smaller ground plans are dropped, their buildings "
         "listed in the problems layer (0 = off)' default='0'/>"
         "  <Option name='SIMPLIFY' type='float' description='Metres: topology-preserving simplification tolerance "
         "(0 = off)' default='0'/>"
         "  <Option name='INPUT_LAYERS' type='string' description='OGR sources: comma-separated layers to read (default: all)'/>"
         "  <Option name='INPUT_WHERE' type='string' description='OGR sources: attribute filter on the layers read (OGR SQL WHERE)'/>"
         "  <Option name='INPUT_SQL' type='string' description='OGR sources: SQL statement whose result layer is read'/>"
         "  <Option name='INPUT_DIALECT' type='string' description='OGR sources: dialect of INPUT_SQL (OGRSQL, SQLITE)'/>"
         "  <Option name='INPUT_OO' type='string' description='OGR sources: comma-separated NAME=VALUE open options of the source driver'/>"
         "  <Option name='ID_FIELD' type='string' description='OGR sources: field holding the building id (default: the FID); glTF / 3D Tiles: the feature property naming a building (default: gml_id, id, name)'/>"
         "  <Option name='GROUP_BY' type='string' description='OGR sources: features sharing this field&apos;s value are one building'/>"
         "  <Option name='INPUT_GEOM_FIELD' type='string' description='OGR sources: the geometry field to read where a layer has several (default: the first)'/>"
         "  <Option name='NUM_THREADS' type='string' description='Threads for every stage: a number or ALL_CPUS "
         "(default: the GDAL_NUM_THREADS config option, else all cores)' default='ALL_CPUS'/>"
         "</OpenOptionList>";
}

std::vector<std::string> inputs_from_connection(const std::string& connection) {
  const std::size_t n = std::strlen(kPrefix);
  if (connection.size() < n || !EQUALN(connection.c_str(), kPrefix, n))
    throw InvalidArgument("not a GroundPlan connection string (expected GROUNDPLAN:<file or folder>): " + connection);
  std::vector<std::string> inputs = gis::input_list(connection.substr(n));
  if (inputs.empty() || (inputs.size() == 1 && inputs[0].empty())) throw InvalidArgument("GROUNDPLAN: names no input file");
  return inputs;
}

namespace {
double parse_double(const char* name, const char* value) {
  double v = 0;
  const char* end = value + std::strlen(value);
  auto [ptr, ec] = std::from_chars(value, end, v);
  if (ec != std::errc() || ptr != end)
    throw InvalidArgument(std::string("open option ") + name + "=" + value + ": not a number");
  return v;
}
}  // namespace

gis::PipelineOptions pipeline_options_from(const std::string& connection, char** open_options) {
  gis::PipelineOptions o;
  o.inputs = inputs_from_connection(connection);
  if (const char* v = CSLFetchNameValue(open_options, "RESOLUTION")) {
    o.union_params.resolution_m = parse_double("RESOLUTION", v);
    if (!(o.union_params.resolution_m >= 0))
      throw InvalidArgument(std::string("open option RESOLUTION=") + v + ": must be >= 0 metres");
  }
  if (const char* v = CSLFetchNameValue(open_options, "DEVICE")) o.union_params.device = gis::device_from_string(v);
  if (const char* v = CSLFetchNameValue(open_options, "FOOTPRINTS")) o.footprints = gis::footprint_mode_from_string(v);
  if (const char* v = CSLFetchNameValue(open_options, "LOD")) {
    const gis::LodChoice lod = gis::parse_lod_choice(v, "open option LOD=");
    o.lod = lod.lod;
    o.lod_refinement = lod.refinement;
  }
  if (const char* v = CSLFetchNameValue(open_options, "T_SRS")) o.t_srs = v;
  if (const char* v = CSLFetchNameValue(open_options, "A_SRS")) o.s_srs = v;
  if (const char* v = CSLFetchNameValue(open_options, "S_SRS")) o.s_srs = v;
  if (const char* v = CSLFetchNameValue(open_options, "PRESET")) o.detail = gis::lod_preset(v);
  if (const char* v = CSLFetchNameValue(open_options, "RESOLUTION_MODE")) o.detail.raster = gis::raster_mode_from_string(v);
  auto lod_value = [&](const char* name, double* field) {
    const char* v = CSLFetchNameValue(open_options, name);
    if (!v) return;
    const double d = parse_double(name, v);
    if (!(d >= 0) || !std::isfinite(d))
      throw InvalidArgument(std::string("open option ") + name + "=" + v + ": must be a number >= 0 (0 = off)");
    *field = d;
  };
  lod_value("SNAP", &o.detail.snap_m);
  lod_value("CLOSE_GAPS", &o.detail.close_gaps_m);
  lod_value("MIN_HOLE_AREA", &o.detail.min_hole_area_m2);
  lod_value("MIN_AREA", &o.detail.min_area_m2);
  lod_value("SIMPLIFY", &o.detail.simplify_m);
  if (const char* v = CSLFetchNameValue(open_options, "ORIGIN")) o.origin = v;
  if (const char* v = CSLFetchNameValue(open_options, "AXIS_ORDER")) o.source_axis = gis::axis_order_from_string(v);
  auto list = [&](const char* name) {
    std::vector<std::string> out;
    const CPLStringList parts(CSLTokenizeString2(CSLFetchNameValueDef(open_options, name, ""), ",", CSLT_HONOURSTRINGS));
    for (int i = 0; i < parts.size(); ++i)
      if (*parts[i]) out.emplace_back(parts[i]);
    return out;
  };
  o.ogr_input.layers = list("INPUT_LAYERS");
  o.ogr_input.open_options = list("INPUT_OO");
  o.ogr_input.where = CSLFetchNameValueDef(open_options, "INPUT_WHERE", "");
  o.ogr_input.sql = CSLFetchNameValueDef(open_options, "INPUT_SQL", "");
  o.ogr_input.dialect = CSLFetchNameValueDef(open_options, "INPUT_DIALECT", "");
  o.ogr_input.id_field = CSLFetchNameValueDef(open_options, "ID_FIELD", "");
  o.ogr_input.group_by = CSLFetchNameValueDef(open_options, "GROUP_BY", "");
  o.ogr_input.geom_field = CSLFetchNameValueDef(open_options, "INPUT_GEOM_FIELD", "");
  if (const char* v = CSLFetchNameValue(open_options, "NUM_THREADS"))
    o.threads = gis::threads_from_string(v, "open option NUM_THREADS");
  else if (const char* g = CPLGetConfigOption("GDAL_NUM_THREADS", nullptr))
    o.threads = gis::threads_from_string(g, "GDAL_NUM_THREADS");
  return o;
}

}  // namespace groundplan::driver
