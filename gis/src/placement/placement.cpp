// SPDX-License-Identifier: MIT
// Model placement (issue 6): local ENU -> geodetic (GeographicLib) -> working CRS (PROJ through
// WorkingFrame, so that the UTM choice, -t_srs handling and notes are the CityGML path's own).
#include <groundplan/error.h>
#include <groundplan/gis/placement.h>

#include "collada/collada_internal.h"

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>

#include <charconv>
#include <cmath>

namespace groundplan::gis {
namespace {

// The working frame takes EPSG:4326 in its authority order: x = latitude, y = longitude.
constexpr const char* kGeodetic = "EPSG:4326";

bool parse_double(std::string_view s, double& v) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size() && std::isfinite(v);
}

CrsOptions geodetic_options(const CrsOptions& crs) {
  CrsOptions o = crs;
  o.source_axis = AxisOrder::Auto;
  return o;
}

}  // namespace

ModelPlacement parse_origin(const std::string& text) {
  ModelPlacement p;
  double v[3] = {0, 0, 0};
  std::size_t n = 0, start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string_view part(text.data() + start, (comma == std::string::npos ? text.size() : comma) - start);
    if (n == 3 || !parse_double(part, v[n]))
      throw InvalidArgument("origin \"" + text + "\" is not lon,lat[,alt] (degrees, degrees, metres), e.g. 8.4,49.0,110");
    ++n;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (n < 2) throw InvalidArgument("origin \"" + text + "\" needs at least lon,lat (degrees)");
  if (std::fabs(v[0]) > 180 || std::fabs(v[1]) > 90)
    throw InvalidArgument("origin \"" + text + "\": longitude must be within ±180 and latitude within ±90 (lon first)");
  p.lon_deg = v[0];
  p.lat_deg = v[1];
  p.alt_m = v[2];
  p.altitude_mode = AltitudeMode::Absolute;
  return p;
}

std::array<double, 16> model_matrix(const ModelPlacement& pl) {
  using namespace detail;
  // KML: "the rotations are applied to a Model in the following order: roll, tilt, heading".
  // Heading turns clockwise seen from above (90° takes the model's +y, north, to east): a negative
  // right-handed angle about z. Tilt and roll: right-handed about x and y (a positive tilt lifts
  // the model's north end, a positive roll its west side).
  const Mat4 heading = rotation(0, 0, 1, -pl.heading_deg);
  const Mat4 tilt = rotation(1, 0, 0, pl.tilt_deg);
  const Mat4 roll = rotation(0, 1, 0, pl.roll_deg);
  return multiply(multiply(heading, multiply(tilt, roll)), scaling(pl.scale_x, pl.scale_y, pl.scale_z));
}

Georeferencer::Georeferencer(const CrsOptions& crs, const std::string& file)
    : frame_(kGeodetic, geodetic_options(crs), file) {}
Georeferencer::~Georeferencer() = default;
Georeferencer::Georeferencer(Georeferencer&&) noexcept = default;
Georeferencer& Georeferencer::operator=(Georeferencer&&) noexcept = default;

void Georeferencer::decide(double lat, double lon) {
  if (!frame_.decided()) {
    frame_.decide(lat, lon);  // the UTM zone of the anchor, not of a vertex
    // WorkingFrame speaks of a source CRS; here the "source" is the models' WGS 84 anchors.
    notes_.clear();
    for (std::string n : frame_.notes()) {
      const std::string from = "source CRS " + std::string(kGeodetic) + " is not projected in metres", centre = "the data's centre";
      if (n.rfind(from, 0) == 0) n = "models are georeferenced in WGS 84 longitude/latitude" + n.substr(from.size());
      if (const auto at = n.find(centre); at != std::string::npos) n.replace(at, centre.size(), "the first model's anchor");
      notes_.push_back(std::move(n));
    }
  }
}

bool Georeferencer::geodetic_to_working(Mesh& mesh, double lat, double lon, std::string* reason) {
  decide(lat, lon);
  return frame_.transform(mesh, reason);
}

bool Georeferencer::place_local(Mesh& mesh, const ModelPlacement& pl, std::string* reason) {
  if (!(std::fabs(pl.lat_deg) <= 90) || !(std::fabs(pl.lon_deg) <= 360) || !std::isfinite(pl.alt_m)) {
    if (reason) *reason = "the model's Location is not a valid longitude/latitude/altitude";
    return false;
  }
  const double h0 = pl.altitude_mode == AltitudeMode::ClampToGround ? 0.0 : pl.alt_m;
  const GeographicLib::LocalCartesian enu(pl.lat_deg, pl.lon_deg, h0, GeographicLib::Geocentric::WGS84());
  const detail::Mat4 m = model_matrix(pl);
  for (Point3& p : mesh.vertices) {
    const Point3 q = detail::apply(m, p);
    double lat = 0, lon = 0, h = 0;
    enu.Reverse(q.x, q.y, q.z, lat, lon, h);
    p = Point3{lat, lon, h};
  }
  return geodetic_to_working(mesh, pl.lat_deg, pl.lon_deg, reason);
}

bool Georeferencer::place_ecef(Mesh& mesh, std::string* reason) {
  if (mesh.vertices.empty()) return true;
  const GeographicLib::Geocentric& earth = GeographicLib::Geocentric::WGS84();
  double cx = 0, cy = 0, cz = 0;
  for (const Point3& p : mesh.vertices) cx += p.x, cy += p.y, cz += p.z;
  const double n = static_cast<double>(mesh.vertices.size());
  double lat0, lon0, h0;
  earth.Reverse(cx / n, cy / n, cz / n, lat0, lon0, h0);
  for (Point3& p : mesh.vertices) {
    double lat = 0, lon = 0, h = 0;
    earth.Reverse(p.x, p.y, p.z, lat, lon, h);
    p = Point3{lat, lon, h};
  }
  return geodetic_to_working(mesh, lat0, lon0, reason);
}

bool Georeferencer::anchor_in_working(double lon_deg, double lat_deg, double& e, double& n) {
  decide(lat_deg, lon_deg);
  double x = lat_deg, y = lon_deg;
  if (!frame_.transform_point(x, y)) return false;
  e = x;
  n = y;
  return true;
}

const WorkingCrs& Georeferencer::working_crs() const { return frame_.working_crs(); }
bool Georeferencer::decided() const { return frame_.decided(); }
const std::vector<std::string>& Georeferencer::notes() const { return notes_; }

}  // namespace groundplan::gis
