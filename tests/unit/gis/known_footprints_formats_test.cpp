// SPDX-License-Identifier: MIT
// Stacked parts and arcades (tests/support/known_footprints.h: plinth, podium, terraces, multi_tower, arcade),
// each one closed mesh of triangles without semantics, written in every mesh format we read and read back:
// CityGML (a MultiSurface, no semantic surfaces), COLLADA in KML, glTF, and an OGR MultiPatch shapefile
// (written by GDAL). The footprint by decomposition is within 0.1 % of the known base, and the check against
// the lowest faces (core/src/footprint/ground_check.h) finds nothing missing; the arcade's is its ground floor
// and pillars, not its shadow.
#include <groundplan/footprint.h>
#include <groundplan/gis/geos_reference.h>
#include <groundplan/gis/reader.h>
#include <gtest/gtest.h>

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "known_footprints.h"
#include "read_all.h"
#include "test_support.h"

namespace groundplan {
namespace {

using Tri = std::array<Point3, 3>;

const char* kFamilies[] = {"plinth", "podium", "podium_corner", "terraces", "multi_tower", "arcade"};

/// The family's closed mesh written as triangles, with its floor (tests/support/known_footprints.h).
const test::KnownFootprint& model(const std::string& family) {
  static const std::vector<test::KnownFootprint> all = test::known_footprints();
  for (const test::KnownFootprint& k : all)
    if (k.family == family && k.writing == test::Writing::Triangles && k.floor) return k;
  throw std::runtime_error("no generated " + family);
}

std::vector<Tri> triangles_of(const Mesh& m) {
  std::vector<Tri> out;
  for (const MeshFace& f : m.faces) {
    const std::uint32_t a = m.ring_offsets[f.first_ring];
    out.push_back({m.vertices[m.indices[a]], m.vertices[m.indices[a + 1]], m.vertices[m.indices[a + 2]]});
  }
  return out;
}

double area_of(const std::vector<Polygon>& polys) {
  auto ring = [](const Ring& r) {
    double a = 0;
    for (std::size_t i = 0; i < r.size(); ++i) a += r[i].x * r[(i + 1) % r.size()].y - r[(i + 1) % r.size()].x * r[i].y;
    return std::fabs(a / 2);
  };
  double a = 0;
  for (const Polygon& p : polys) {
    a += ring(p.outer);
    for (const Ring& h : p.holes) a -= ring(h);
  }
  return a;
}

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

constexpr double kX0 = 500000, kY0 = 5400000;  // EPSG:25832 offsets for CityGML

std::string citygml(const std::vector<Tri>& tris) {
  std::string s = R"(<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml">
<gml:boundedBy><gml:Envelope srsName="EPSG:25832" srsDimension="3"><gml:lowerCorner>500000 5400000 0</gml:lowerCorner><gml:upperCorner>500100 5400100 100</gml:upperCorner></gml:Envelope></gml:boundedBy>
<core:cityObjectMember><bldg:Building gml:id="b1"><bldg:lod2MultiSurface><gml:MultiSurface>
)";
  for (const Tri& t : tris) {
    s += "<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">";
    for (int k = 0; k <= 3; ++k) {
      const Point3& p = t[k % 3];
      s += num(p.x + kX0) + " " + num(p.y + kY0) + " " + num(p.z) + " ";
    }
    s += "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>\n";
  }
  s += "</gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></core:cityObjectMember></core:CityModel>\n";
  return s;
}

/// COLLADA, Z_UP metres, one <triangles> element.
std::string collada(const std::vector<Tri>& tris) {
  std::string pos, idx;
  for (const Tri& t : tris)
    for (const Point3& p : t) pos += num(p.x) + " " + num(p.y) + " " + num(p.z) + " ";
  for (std::size_t i = 0; i < 3 * tris.size(); ++i) idx += std::to_string(i) + " ";
  const std::string n = std::to_string(3 * tris.size());
  return R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit meter="1" name="meter"/><up_axis>Z_UP</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="pos"><float_array id="pa" count=")" + std::to_string(9 * tris.size()) + R"(">)" + pos + R"(</float_array>
   <technique_common><accessor source="#pa" count=")" + n + R"(" stride="3"><param name="X" type="float"/>
    <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#pos"/></vertices>
  <triangles count=")" + std::to_string(tris.size()) + R"("><input semantic="VERTEX" source="#v" offset="0"/><p>)" + idx + R"(</p></triangles>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
 </library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>)";
}

// Near 11.4° E, 48.1° N: UTM 32N's scale is within 2e-5 of 1 there, so areas keep their metres.
constexpr double kLon = 11.4, kLat = 48.1;

std::string kml(const std::string& href) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark id="b1"><Model><Location><longitude>)" + num(kLon) +
         "</longitude><latitude>" + num(kLat) + "</latitude><altitude>0</altitude></Location><Link><href>" + href +
         "</href></Link></Model></Placemark></Document></kml>";
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const unsigned v = (unsigned char)in[i] << 16 | (i + 1 < in.size() ? (unsigned char)in[i + 1] << 8 : 0) |
                       (i + 2 < in.size() ? (unsigned char)in[i + 2] : 0);
    out += t[v >> 18];
    out += t[(v >> 12) & 63];
    out += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? t[v & 63] : '=';
  }
  return out;
}

/// glTF 2.0, y up (z up -> (x, z, -y)), float positions, u32 indices, the buffer as a data URI.
std::string gltf(const std::vector<Tri>& tris) {
  std::string bin;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (const Tri& t : tris)
    for (const Point3& p : t) {
      const float v[3] = {static_cast<float>(p.x), static_cast<float>(p.z), static_cast<float>(-p.y)};
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
      bin.append(reinterpret_cast<const char*>(v), sizeof v);
    }
  const std::size_t pos_bytes = bin.size(), n = 3 * tris.size();
  for (std::uint32_t i = 0; i < n; ++i) bin.append(reinterpret_cast<const char*>(&i), 4);
  std::string j = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"name":"b1"}],)";
  j += R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)";
  j += R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(n) + R"(,"type":"VEC3","min":[)" +
       num(lo[0]) + "," + num(lo[1]) + "," + num(lo[2]) + "],\"max\":[" + num(hi[0]) + "," + num(hi[1]) + "," + num(hi[2]) +
       R"(]},{"bufferView":1,"componentType":5125,"count":)" + std::to_string(n) + R"(,"type":"SCALAR"}],)";
  j += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(pos_bytes) +
       R"(},{"buffer":0,"byteOffset":)" + std::to_string(pos_bytes) + R"(,"byteLength":)" + std::to_string(4 * n) + "}],";
  j += R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) + R"(,"uri":"data:application/octet-stream;base64,)" +
       base64(bin) + "\"}]}";
  return j;
}

/// An ESRI Shapefile MultiPatch written by GDAL: one feature, the triangles as a TIN Z, EPSG:25832 offsets.
std::string multipatch(const test::TempDir& tmp, const std::vector<Tri>& tris) {
  GDALAllRegister();
  const std::string path = (tmp.path / "b.shp").string();
  GDALDriver* drv = GetGDALDriverManager()->GetDriverByName("ESRI Shapefile");
  if (!drv) return "";
  GDALDataset* ds = drv->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
  OGRSpatialReference srs;
  srs.importFromEPSG(25832);
  char** opts = CSLSetNameValue(nullptr, "SHPT", "MULTIPATCH");
  OGRLayer* lyr = ds->CreateLayer("b", &srs, wkbTINZ, opts);
  CSLDestroy(opts);
  OGRFieldDefn id("id", OFTString);
  lyr->CreateField(&id);
  OGRTriangulatedSurface tin;
  for (const Tri& t : tris) {
    OGRPoint a(t[0].x + kX0, t[0].y + kY0, t[0].z), b(t[1].x + kX0, t[1].y + kY0, t[1].z), c(t[2].x + kX0, t[2].y + kY0, t[2].z);
    OGRTriangle tri(a, b, c);
    tin.addGeometry(&tri);
  }
  OGRFeature* f = OGRFeature::CreateFeature(lyr->GetLayerDefn());
  f->SetField("id", "b1");
  f->SetGeometry(&tin);
  const bool ok = lyr->CreateFeature(f) == OGRERR_NONE;
  OGRFeature::DestroyFeature(f);
  GDALClose(ds);
  return ok ? path : "";
}

void expect_known_base(const test::KnownFootprint& k, const test::Read& r, const std::string& format) {
  ASSERT_EQ(r.meshes.size(), 1u) << k.family << " " << format << "\n" << r.all();
  FootprintParams params;
  params.source = FootprintSource::Decompose;
  const FootprintResult f = make_footprint(r.meshes[0], params);
  ASSERT_TRUE(f.ok) << k.family << " " << format << ": " << f.reason;
  EXPECT_EQ(f.method, FootprintMethod::Decomposition) << k.family << " " << format << ": " << f.note;
  const double area = area_of(f.footprint.polygons);
  EXPECT_NEAR(area, k.true_area_m2, 1e-3 * k.true_area_m2)
      << k.family << " " << format << " (shadow " << k.shadow_area_m2 << ")";
  EXPECT_TRUE(f.misses_ground.empty()) << k.family << " " << format << ": " << f.misses_ground;
}

TEST(KnownFootprintFormats, CityGmlWithoutSemanticSurfaces) {
  test::TempDir tmp("groundplan_formats");
  for (const char* fam : kFamilies) {
    const test::KnownFootprint& k = model(fam);
    expect_known_base(k, test::read(tmp.file(std::string(fam) + ".gml", citygml(triangles_of(k.mesh)))), "CityGML");
  }
}

TEST(KnownFootprintFormats, ColladaInKml) {
  test::TempDir tmp("groundplan_formats");
  for (const char* fam : kFamilies) {
    const test::KnownFootprint& k = model(fam);
    tmp.file(std::string(fam) + ".dae", collada(triangles_of(k.mesh)));
    expect_known_base(k, test::read(tmp.file(std::string(fam) + ".kml", kml(std::string(fam) + ".dae"))), "KML/COLLADA");
  }
}

TEST(KnownFootprintFormats, Gltf) {
  test::TempDir tmp("groundplan_formats");
  gis::ReadOptions opt;
  opt.origin = num(kLon) + "," + num(kLat) + ",0";
  for (const char* fam : kFamilies) {
    const test::KnownFootprint& k = model(fam);
    expect_known_base(k, test::read(tmp.file(std::string(fam) + ".gltf", gltf(triangles_of(k.mesh))), opt), "glTF");
  }
}

TEST(KnownFootprintFormats, OgrMultiPatch) {
  for (const char* fam : kFamilies) {
    test::TempDir tmp("groundplan_formats");
    const test::KnownFootprint& k = model(fam);
    const std::string path = multipatch(tmp, triangles_of(k.mesh));
    ASSERT_FALSE(path.empty()) << "GDAL could not write the MultiPatch shapefile";
    expect_known_base(k, test::read(path), "MultiPatch");
  }
}

}  // namespace
}  // namespace groundplan
