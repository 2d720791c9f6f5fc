// SPDX-License-Identifier: MIT
#pragma once
// KML / KMZ reader (DESIGN.md stage 1, issue 6): every <Placemark>'s <Model> (inside Documents and
// Folders at any depth, and inside MultiGeometry) with its Location, altitudeMode, Orientation,
// Scale and Link/href to a COLLADA file. Both KML namespaces (http://www.opengis.net/kml/2.2 and
// http://earth.google.com/kml/2.x) and none; elements in any order; comments anywhere.
//
// A KMZ is read through GDAL's /vsizip/: its root .kml (doc.kml first), hrefs relative to that .kml
// inside the archive. A plain .kml resolves hrefs in its own folder tree.
//
// Security: nothing is fetched. http(s)/ftp/file URLs, absolute paths and hrefs that climb out of
// the archive (or out of the .kml's folder; symlinks included) are Problems, never opened.
// NetworkLinks to .kml files are followed as a viewer would (issue 16): hrefs relative to the
// linking file ('\' taken as '/'), inside the input's folder or archive only, depth-limited, each
// file read once (cycles and repeated links are reported, not followed); remote, absolute and
// escaping links are Problems, never opened. Unpacked bytes are bounded per entry and per input
// (zip bombs: the stated size is checked before reading, the bytes read while reading). XML as in
// the other readers: no DTD, no entities, depth limit.
#include <groundplan/gis/collada.h>
#include <groundplan/gis/placement.h>
#include <groundplan/mesh.h>
#include <groundplan/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace groundplan::gis {

struct KmlOptions {
  ColladaOptions collada;
  std::uint64_t max_entry_bytes = std::uint64_t{256} << 20;  // one .kml / .dae, unpacked
  std::uint64_t max_total_bytes = std::uint64_t{1} << 30;    // everything read for one input
  std::size_t max_xml_depth = 256;
  std::size_t max_network_link_depth = 32;   // NetworkLink chains deeper than this: NETWORK_LINK_TOO_DEEP
  std::size_t max_linked_files = 100000;     // .kml files read through NetworkLinks, per input
};

struct KmlInfo {
  std::string file;
  bool kmz = false;
  std::string kml_path;          // the .kml actually parsed (a /vsizip/ path for a KMZ)
  std::size_t placemarks = 0;
  std::size_t models = 0;        // <Model> elements met
  std::size_t meshes = 0;        // models delivered
  std::size_t network_links = 0; // NetworkLinks met
  std::size_t linked_files = 0;  // .kml files read through NetworkLinks
  std::uint64_t bytes = 0;       // unpacked bytes read (KML + COLLADA)
};

/// One model: the mesh in its local frame (x east, y north, z up, metres: COLLADA unit and up_axis
/// applied; Scale and Orientation NOT applied) and where it goes. Mesh::source_id is the Placemark
/// id (else Model id, else Placemark name, else "placemark N"), "/model K" added when a Placemark
/// has several. The mesh may be moved from.
using KmlModelCallback = std::function<void(Mesh&&, const ModelPlacement&)>;

/// Reads a .kml or .kmz (local or VSI path). Per-model defects (no Location, unreadable or missing
/// COLLADA: code LINK_TARGET_NOT_FOUND, remote or escaping href, NetworkLink not followed, linked
/// .kml unreadable: BAD_NETWORK_LINK_TARGET) are Problems and
/// reading goes on. Throws InputError naming the file when the file cannot be read, is not a zip
/// (.kmz) or holds no .kml, is not well-formed XML, or passes the byte limits. Exceptions thrown
/// by `on_model` propagate.
void read_kml(const std::string& path, const KmlOptions& options, const KmlModelCallback& on_model,
              std::vector<Problem>& problems, KmlInfo& info);

/// Why an href cannot be followed; Ok when `resolved` holds a path inside `root`.
enum class HrefStatus { Ok, Empty, Remote, Absolute, Escapes, Invalid };

/// Resolves an href (percent-decoded, '\' taken as '/') against `base_dir` ("" or "dir/" inside
/// the container) lexically: `resolved` is the normalised relative path inside the container.
HrefStatus resolve_href(const std::string& href, const std::string& base_dir, std::string& resolved);

}  // namespace groundplan::gis
