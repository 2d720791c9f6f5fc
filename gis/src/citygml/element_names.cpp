// SPDX-License-Identifier: MIT
#include "citygml/element_names.h"

#include <cstring>
#include <initializer_list>
#include <utility>

namespace groundplan::gis::citygml {
namespace {

constexpr char kSep = ' ';  // namespace URI / local name separator: URIs cannot hold a space

/// Local name -> Tag in a power-of-two open-addressing table (fixed at start-up, read-only after).
class TagTable {
 public:
  TagTable(std::initializer_list<std::pair<std::string_view, Tag>> entries) {
    for (const auto& [name, tag] : entries) {
      std::size_t h = hash(name);
      while (!slots_[h].name.empty()) h = (h + 1) & kMask;
      slots_[h] = Slot{name, tag};
    }
  }
  Tag find(std::string_view local) const {
    if (local.empty()) return Tag::None;
    for (std::size_t h = hash(local);; h = (h + 1) & kMask) {
      const Slot& s = slots_[h];
      if (s.name.empty()) return Tag::None;
      if (s.name.size() == local.size() && std::memcmp(s.name.data(), local.data(), local.size()) == 0) return s.tag;
    }
  }

 private:
  static constexpr std::size_t kSize = 256;  // > 4x the entries: probes stay short, an empty slot always exists
  static constexpr std::size_t kMask = kSize - 1;
  struct Slot {
    std::string_view name;
    Tag tag = Tag::None;
  };
  static std::size_t hash(std::string_view s) {
    const std::size_t n = s.size();
    const auto c = [&](std::size_t k) { return static_cast<std::size_t>(static_cast<unsigned char>(s[k])); };
    return (n * 97 + c(0) * 31 + c(n / 2) * 7 + c(n - 1) * 3 + (n > 4 ? c(3) : 0)) & kMask;
  }
  Slot slots_[kSize];
};

// clang-format off
const TagTable kCityGmlTags = {
      {"CityModel", Tag::CityModel},
      {"Building", Tag::Building},
      {"BuildingPart", Tag::BuildingPart},
      {"GroundSurface", Tag::Ground},
      {"RoofSurface", Tag::Roof},
      {"WallSurface", Tag::Wall},
      {"ClosureSurface", Tag::Closure},
      {"OuterCeilingSurface", Tag::OtherSurface},
      {"OuterFloorSurface", Tag::OtherSurface},
      {"Window", Tag::OtherSurface},
      {"Door", Tag::OtherSurface},
      {"DoorSurface", Tag::OtherSurface},
      {"WindowSurface", Tag::OtherSurface},
      // Inside a building but not part of its shell: parsed into the side mesh (xlink targets only).
      {"BuildingInstallation", Tag::Excluded},
      {"IntBuildingInstallation", Tag::Excluded},
      {"Room", Tag::Excluded},
      {"BuildingFurniture", Tag::Excluded},
      {"BuildingRoom", Tag::Excluded},
      {"Storey", Tag::Excluded},
      {"BuildingUnit", Tag::Excluded},
      {"BuildingConstructiveElement", Tag::Excluded},
      {"interiorRoom", Tag::Excluded},
      {"interiorFurniture", Tag::Excluded},
      {"outerBuildingInstallation", Tag::Excluded},
      {"interiorBuildingInstallation", Tag::Excluded},
      {"buildingInstallation", Tag::Excluded},
      {"buildingRoom", Tag::Excluded},
      {"buildingFurniture", Tag::Excluded},
      {"buildingSubdivision", Tag::Excluded},
      {"buildingConstructiveElement", Tag::Excluded},
      // Never geometry of the building's shell, never an xlink target we need.
      {"appearance", Tag::Skip},
      {"address", Tag::Skip},
      {"externalReference", Tag::Skip},
      {"measuredHeight", Tag::MeasuredHeight},
};

const TagTable kGmlTags = {
      {"Polygon", Tag::Polygon},
      {"PolygonPatch", Tag::Polygon},
      {"Triangle", Tag::Polygon},
      {"Rectangle", Tag::Polygon},
      {"LinearRing", Tag::LinearRing},
      {"exterior", Tag::Exterior},
      {"outerBoundaryIs", Tag::Exterior},
      {"interior", Tag::Interior},
      {"innerBoundaryIs", Tag::Interior},
      {"posList", Tag::PosList},
      {"pos", Tag::Pos},
      {"coordinates", Tag::Coordinates},
      {"OrientableSurface", Tag::OrientableSurface},
      {"Envelope", Tag::Envelope},
      {"lowerCorner", Tag::LowerCorner},
      {"upperCorner", Tag::UpperCorner},
      {"name", Tag::Name},
      {"Ring", Tag::CurveRing},
};
// clang-format on

}  // namespace

Ns classify_ns(std::string_view uri) {
  if (uri.empty()) return Ns::None;
  if (uri == "http://www.opengis.net/gml" || uri == "http://www.opengis.net/gml/3.2") return Ns::Gml;
  if (uri.starts_with("http://www.opengis.net/citygml/")) return Ns::CityGml;
  if (uri == "http://www.w3.org/1999/xlink") return Ns::Xlink;
  return Ns::Other;
}

Tag citygml_tag(std::string_view local) { return kCityGmlTags.find(local); }
Tag gml_tag(std::string_view local) { return kGmlTags.find(local); }

SplitName NameSplitter::split(const char* name) {
  // The URI that matched last, then the others: "URI " must be a prefix of the name. A local name holds
  // no space and a URI none either, so a match is the split expat made.
  const std::size_t n = known_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = (last_ + i) % n;
    const std::string& u = known_[k].uri;
    if (std::strncmp(name, u.data(), u.size()) == 0 && name[u.size()] == kSep) {
      last_ = k;
      return SplitName{std::string_view(name, u.size()), std::string_view(name + u.size() + 1), known_[k].ns};
    }
  }
  const char* sp = std::strrchr(name, kSep);
  if (!sp) return SplitName{{}, std::string_view(name), Ns::None};
  const std::string_view uri(name, static_cast<std::size_t>(sp - name));
  const Ns ns = classify_ns(uri);
  if (known_.size() < kMaxKnown) {
    known_.push_back(Known{std::string(uri), ns});
    last_ = known_.size() - 1;
  }
  return SplitName{uri, std::string_view(sp + 1), ns};
}

Attrs scan_attrs(const char** atts, NameSplitter& names) {
  Attrs a;
  for (; *atts; atts += 2) {
    const char* n = atts[0];
    switch (n[0]) {  // no namespace: the name itself (a URI starts with a scheme, never one of these alone)
      case 's':
        if (!std::strcmp(n, "srsName")) { a.srs_name = atts[1]; continue; }
        if (!std::strcmp(n, "srsDimension")) { a.srs_dimension = atts[1]; continue; }
        break;
      case 'o':
        if (!std::strcmp(n, "orientation")) { a.orientation = atts[1]; continue; }
        break;
      case 'c':
        if (!std::strcmp(n, "cs")) { a.cs = atts[1]; continue; }
        break;
      case 't':
        if (!std::strcmp(n, "ts")) { a.ts = atts[1]; continue; }
        break;
      case 'd':
        if (!std::strcmp(n, "decimal")) { a.decimal = atts[1]; continue; }
        break;
      default:
        break;
    }
    const SplitName s = names.split(n);
    if (s.ns == Ns::Gml && s.local == "id") a.gml_id = atts[1];
    else if (s.ns == Ns::Xlink && s.local == "href") a.href = atts[1];
  }
  return a;
}

/// srsDimension "2" or "3" (spaces around allowed) -> 2 or 3; anything else (a claim of 1e9 dimensions,
/// a negative or a non-number) -> 0.
int srs_dimension_value(std::string_view v) {
  while (!v.empty() && (v.front() == ' ' || v.front() == '\t' || v.front() == '\n' || v.front() == '\r')) v.remove_prefix(1);
  while (!v.empty() && (v.back() == ' ' || v.back() == '\t' || v.back() == '\n' || v.back() == '\r')) v.remove_suffix(1);
  return v == "2" ? 2 : v == "3" ? 3 : 0;
}

/// "lod2Solid" -> lod 2, surface geometry; "lod2TerrainIntersection" -> skip. Returns false if not lodN*.
bool parse_lod_property(std::string_view local, std::uint8_t& lod, Tag& tag, SurfaceKind& kind) {
  if (local.size() < 5 || !local.starts_with("lod") || local[3] < '0' || local[3] > '4') return false;
  lod = static_cast<std::uint8_t>(local[3] - '0');
  std::string_view rest = local.substr(4);
  kind = SurfaceKind::Unknown;
  if (rest == "Solid" || rest == "MultiSurface" || rest == "Geometry" || rest == "CompositeSurface") {
    tag = Tag::LodSurface;
  } else if (rest == "FootPrint") {
    tag = Tag::LodSurface;
    kind = SurfaceKind::FootPrint;
  } else if (rest == "RoofEdge") {
    tag = Tag::LodSurface;
    kind = SurfaceKind::RoofEdge;
  } else {
    tag = Tag::LodSkip;  // MultiCurve, TerrainIntersection, ImplicitRepresentation, Point, attributes like lod1HeightType
  }
  return true;
}

}  // namespace groundplan::gis::citygml
