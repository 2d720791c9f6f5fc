// SPDX-License-Identifier: MIT
#pragma once
// What the CityGML reader knows by name (issue 6), and how it looks names up fast (issue 14): expat in
// namespace mode hands every element and attribute over as "URI<space>local"; NameSplitter remembers
// the namespace URIs of the document (a few) and recognises them by one memcmp instead of a strlen, a
// backward scan and string compares per element; TagTable finds a local name in a small open-addressing
// table instead of std::hash over the name.
#include <groundplan/mesh.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis::citygml {

enum class Ns : std::uint8_t { None, Gml, CityGml, Xlink, Other };

enum class Tag : std::uint8_t {
  None,
  // CityGML (any module, any version)
  CityModel, Building, BuildingPart, Ground, Roof, Wall, Closure, OtherSurface, Excluded, Skip, MeasuredHeight,
  LodSurface, LodSkip,
  // GML
  Polygon, LinearRing, Exterior, Interior, PosList, Pos, Coordinates, OrientableSurface, Envelope, LowerCorner,
  UpperCorner, Name, CurveRing,
};

/// GML 3.1 / 3.2, any CityGML module of any version, XLink, another namespace, or none.
Ns classify_ns(std::string_view uri);

/// The reader's tag for a local name in a CityGML namespace (Tag::None if it has none).
Tag citygml_tag(std::string_view local);
/// The reader's tag for a local name in GML's namespace (Tag::None if it has none).
Tag gml_tag(std::string_view local);

struct SplitName {
  std::string_view uri;  // empty: no namespace
  std::string_view local;
  Ns ns = Ns::None;
};

/// Splits expat's "URI local" names; the URIs seen are kept (a document uses a handful), so the usual
/// name costs one compare against the last URI that matched.
class NameSplitter {
 public:
  SplitName split(const char* name);

 private:
  struct Known {
    std::string uri;
    Ns ns;
  };
  static constexpr std::size_t kMaxKnown = 32;  // more namespaces than this: the rest are split the slow way
  std::vector<Known> known_;
  std::size_t last_ = 0;  // index of the URI that matched last
};

/// Attribute names in namespace mode: "srsName" (no namespace) or "URI local".
struct Attrs {
  const char* gml_id = nullptr;
  const char* href = nullptr;
  const char* srs_name = nullptr;
  const char* srs_dimension = nullptr;
  const char* orientation = nullptr;
  const char* cs = nullptr;
  const char* ts = nullptr;
  const char* decimal = nullptr;
};

/// The attributes the reader uses, from expat's null-terminated name/value array.
Attrs scan_attrs(const char** atts, NameSplitter& names);

/// srsDimension "2" or "3" (spaces around allowed) -> 2 or 3; anything else (a claim of 1e9 dimensions,
/// a negative or a non-number) -> 0.
int srs_dimension_value(std::string_view v);

/// "lod2Solid" -> lod 2, surface geometry; "lod2TerrainIntersection" -> skip. Returns false if not lodN*.
bool parse_lod_property(std::string_view local, std::uint8_t& lod, Tag& tag, SurfaceKind& kind);

}  // namespace groundplan::gis::citygml
