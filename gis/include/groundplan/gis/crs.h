// SPDX-License-Identifier: MIT
#pragma once
// srsName parsing and the working frame (DESIGN.md stage 2, issue 6). The working CRS is projected
// and metric: the source's horizontal CRS when it is, else the WGS 84 UTM zone of the data's centre
// (EPSG:326xx / 327xx), or what the user names (-t_srs). Meshes are transformed in place: x, y
// become easting, northing in metres; z becomes metres too (its datum kept): the unit of the source's
// vertical CRS where it names one (compound "EPSG:2263+6360": NAVD88 height in US survey feet), else of its
// horizontal CRS when projected (EPSG:2263 alone: feet), else metres (ellipsoidal heights).
//
// Axis order: a geographic source is read in its authority order (EPSG:4326, 4979, 6697 ... write
// latitude first, as CityGML files must: "35.7559 139.5542 55.03" is lat, lon, h); a projected source
// is read easting first whatever its EPSG axis order says, as every CityGML producer writes it.
// CrsOptions::source_axis overrides this for files that break the rule.
//
// Not thread-safe: one WorkingFrame (it owns a PJ_CONTEXT while it lives) is used by one thread at a time.
// Frames are cheap to make again: a finished frame's PROJ objects are kept and handed to the next frame
// made with the same arguments (working_frame.cpp says why and how).
#include <groundplan/mesh.h>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis {

/// An srsName taken apart. Understood forms: EPSG:n, EPSG:h+v, urn:ogc:def:crs:EPSG::n,
/// urn:ogc:def:crs:EPSG:6.12:n, urn:x-ogc:def:crs:EPSG:n, compound urn:ogc:def:crs,crs:EPSG::h,crs:EPSG::v,
/// http(s)://www.opengis.net/def/crs/EPSG/0/n, .../def/crs-compound?1=...&2=...,
/// http://www.opengis.net/gml/srs/epsg.xml#n, AdV urn:adv:crs:ETRS89_UTM32*DE_DHHN92_NH (-> 25832 + 5783),
/// "#id" (a CRS defined inside the file: treated as local). Anything else is handed to PROJ as is
/// (WKT, PROJ strings, ESRI:n ...).
struct SrsName {
  std::string text;        // as written
  int epsg = 0;            // first (horizontal, or the only) EPSG code; 0 if none
  int vertical_epsg = 0;   // second component of a compound name; 0 if none
  bool local = false;      // empty, "#..." or an engineering/local CRS: no georeference
  std::string definition;  // what PROJ is given: "EPSG:25832" or the text itself; empty when local
};
SrsName parse_srs_name(std::string_view srs_name);

enum class AxisOrder {
  Auto,       // authority order for geographic CRSs, easting first for projected ones
  EastNorth,  // x = longitude / easting
  NorthEast,  // x = latitude / northing
};

struct CrsOptions {
  std::string target_srs;            // -t_srs: any form parse_srs_name understands; empty = automatic
  AxisOrder source_axis = AxisOrder::Auto;
  /// GDAL's GML convention (its GML driver, GML_CONSIDER_EPSG_AS_URN=NO): an srsName written in the short
  /// form "EPSG:n" is read longitude/easting first even where the EPSG axis order is latitude first; the
  /// URN and URL forms keep the authority order. Applies with source_axis Auto only; set for CityGML.
  bool gml_short_epsg_east_first = false;
};

/// The working CRS, for the OGR layer.
struct WorkingCrs {
  bool known = false;     // false: source CRS unknown, coordinates kept as written
  int epsg = 0;           // 0 when it has no EPSG code
  std::string wkt;        // WKT2:2019; empty when unknown
  std::string name;       // e.g. "WGS 84 / UTM zone 54N"
  std::string definition; // "EPSG:32654", or the PROJ string / WKT it came from
};

class WorkingFrame {
 public:
  /// `source_srs`: the file's srsName as written ("" = none). `file` names the file in messages.
  /// Throws InvalidArgument if options.target_srs is not a projected metric CRS PROJ knows, or if a
  /// target is asked for while the source CRS is unknown.
  WorkingFrame(const std::string& source_srs, const CrsOptions& options = {}, const std::string& file = {});
  ~WorkingFrame();
  WorkingFrame(WorkingFrame&&) noexcept;
  WorkingFrame& operator=(WorkingFrame&&) noexcept;
  WorkingFrame(const WorkingFrame&) = delete;
  WorkingFrame& operator=(const WorkingFrame&) = delete;

  /// Fixes the working CRS from a point of the data as written (the envelope's centre, or a first
  /// vertex): needed for the UTM choice. Throws InputError when the point contradicts the source CRS
  /// (e.g. EPSG:4326 with values in the hundreds of thousands). Only the first call counts.
  void decide(double x_as_written, double y_as_written);
  bool decided() const;

  /// Transforms x, y of every vertex in place (z kept); decides from the mesh first if needed.
  /// Returns false and sets `reason` when a vertex cannot be transformed (the mesh is then unusable).
  bool transform(Mesh& mesh, std::string* reason = nullptr);

  /// Transforms one point as written (for tests and anchors). Same rules as transform().
  bool transform_point(double& x, double& y) const;

  /// Issue 16: when the point (x, y as written: a building's centre) lies far (> 2 degrees) outside the
  /// source CRS's area of use (PROJ's proj_get_area_of_use), one sentence naming the point, the area, the
  /// likely cause (axes swapped, degrees under a projected label, metres under a geographic one) and the
  /// flag that mends it (--axis-order, -s_srs); empty when the point fits or PROJ knows no area.
  std::string area_of_use_mismatch(double x_as_written, double y_as_written) const;

  bool source_known() const;            // false: no or local srsName; coordinates pass unchanged
  bool source_geographic() const;
  bool identity() const;                // nothing to do (projected metric source in metres, no target)
  double height_to_metre() const;       // what transform() multiplies z by (1: heights in metres already)
  const SrsName& source() const;
  const WorkingCrs& working_crs() const;  // valid after decide() (or at once when no choice is needed)
  /// Things a person should know (CRS unknown, axis order guessed ...): one sentence each.
  const std::vector<std::string>& notes() const;

  struct Impl;  // opaque

 private:
  static std::unique_ptr<Impl> take_pooled(const std::string& key);
  static void give_back(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// How many frames have made their PROJ objects afresh since the process started (the others reused a
/// finished frame's). For tests and statistics.
std::size_t working_frame_setups();

/// The WGS 84 UTM zone EPSG code (326zz north, 327zz south) for a longitude/latitude in degrees.
int utm_epsg_for(double lon_deg, double lat_deg);

}  // namespace groundplan::gis
