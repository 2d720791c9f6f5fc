// SPDX-License-Identifier: MIT
#pragma once
// Placing model-frame meshes (KML Model + COLLADA, glTF) in the working CRS (DESIGN.md stage 2,
// issue 6): local east-north-up metres at an anchor -> geodetic with GeographicLib::LocalCartesian
// (WGS 84) -> the working CRS with PROJ (gis/crs.h WorkingFrame, source EPSG:4326). ECEF input
// (glTF with CESIUM_RTC or a 3D-Tiles-style root transform) -> geodetic with GeographicLib::Geocentric.
//
// Heights: vertices keep the ellipsoidal height GeographicLib gives (anchor height + local z, up to
// the Earth's curvature: 0.2 mm at 50 m). Only the footprint's z range depends on it.
//
// Not thread-safe: one Georeferencer per thread (it owns a WorkingFrame and so a PJ_CONTEXT).
#include <groundplan/gis/crs.h>
#include <groundplan/mesh.h>

#include <array>
#include <string>
#include <vector>

namespace groundplan::gis {

/// KML <altitudeMode> (and gx:altitudeMode: clampToSeaFloor ~ clampToGround, relativeToSeaFloor ~
/// relativeToGround). The terrain is not known here, so the ground is taken as the ellipsoid:
/// clampToGround puts the model's origin at height 0 (altitude ignored, as KML says), relativeToGround
/// at `altitude`, absolute at `altitude` (KML means above the EGM96 geoid; the geoid undulation, tens
/// of metres, is not applied: it shifts z only, never x/y).
enum class AltitudeMode { ClampToGround, RelativeToGround, Absolute };

/// Where and how a model sits (KML <Model>): anchor and rotations in degrees, scale factors.
struct ModelPlacement {
  double lon_deg = 0, lat_deg = 0, alt_m = 0;
  AltitudeMode altitude_mode = AltitudeMode::ClampToGround;
  double heading_deg = 0;  // about z (up), clockwise seen from above: 90 turns the model's north to east
  double tilt_deg = 0;     // about x (east), clockwise seen from +x
  double roll_deg = 0;     // about y (north), clockwise seen from +y
  double scale_x = 1, scale_y = 1, scale_z = 1;
};

/// Parses "lon,lat[,alt]" (degrees, metres; spaces allowed). Throws InvalidArgument with the reason.
ModelPlacement parse_origin(const std::string& lon_lat_alt);

/// The 4x4 row-major matrix (column vectors) of Scale, then Orientation (KML: roll, then tilt, then
/// heading: R = heading · tilt · roll), in the local ENU frame; no translation.
std::array<double, 16> model_matrix(const ModelPlacement& placement);

class Georeferencer {
 public:
  /// `crs.target_srs` empty: the working CRS is the WGS 84 UTM zone of the first anchor placed.
  /// Throws InvalidArgument for a target that is not a projected metric CRS.
  explicit Georeferencer(const CrsOptions& crs = {}, const std::string& file = {});
  ~Georeferencer();
  Georeferencer(Georeferencer&&) noexcept;
  Georeferencer& operator=(Georeferencer&&) noexcept;

  /// Mesh in the model's local frame (x east, y north, z up, metres) -> working CRS: model_matrix,
  /// then the anchor. Returns false with `reason` when a vertex cannot be transformed.
  bool place_local(Mesh& mesh, const ModelPlacement& placement, std::string* reason = nullptr);
  /// Mesh in ECEF metres (WGS 84) -> working CRS.
  bool place_ecef(Mesh& mesh, std::string* reason = nullptr);

  /// The working CRS: valid once something was placed (or at once when a target was given).
  const WorkingCrs& working_crs() const;
  bool decided() const;
  const std::vector<std::string>& notes() const;
  /// One anchor's position in the working CRS (easting, northing): for tests and messages.
  bool anchor_in_working(double lon_deg, double lat_deg, double& e, double& n);

 private:
  void decide(double lat_deg, double lon_deg);
  bool geodetic_to_working(Mesh& mesh, double lat_decide, double lon_decide, std::string* reason);
  WorkingFrame frame_;
  std::vector<std::string> notes_;
};

}  // namespace groundplan::gis
