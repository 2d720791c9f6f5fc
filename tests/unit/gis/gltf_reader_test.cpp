// SPDX-License-Identifier: MIT
// glTF 2.0 / GLB reader (issue 6): files made here (a unit cube as .gltf with a data-URI buffer,
// as .glb, with CESIUM_RTC, with an ECEF root node), placement against PROJ's own transformation
// of the anchor, and hostile files (accessors and indices out of range, buffers outside the folder).
#include <groundplan/error.h>
#include <groundplan/gis/reader.h>

#include <gtest/gtest.h>
#include <proj.h>

#include "read_all.h"
#include "test_config.h"

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "test_support.h"

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;


std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
  }
  if (i + 1 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16;
    out += {t[v >> 18], t[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
  }
  return out;
}

/// A unit cube in glTF's y-up frame: x, z in [-0.5, 0.5], y (up) in [0, 1]; 12 triangles, u16 indices.
std::string cube_buffer() {
  const float v[8][3] = {{-.5f, 0, -.5f}, {.5f, 0, -.5f}, {.5f, 0, .5f}, {-.5f, 0, .5f},
                         {-.5f, 1, -.5f}, {.5f, 1, -.5f}, {.5f, 1, .5f}, {-.5f, 1, .5f}};
  const std::uint16_t idx[36] = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1,
                                 1, 5, 6, 1, 6, 2, 2, 6, 7, 2, 7, 3, 3, 7, 4, 3, 4, 0};
  std::string b(reinterpret_cast<const char*>(v), sizeof v);
  b.append(reinterpret_cast<const char*>(idx), sizeof idx);
  return b;  // 96 + 72 = 168 bytes
}

/// The glTF JSON; `buffer_uri` empty = GLB's BIN chunk. `extra` lands at the top level.
std::string cube_json(const std::string& buffer_uri, const std::string& node = R"({"mesh":0,"name":"cube"})",
                      const std::string& extra = "", const std::string& pos_count = "8",
                      const std::string& idx_count = "36") {
  std::string j = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[)" + node + "],";
  j += R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)";
  j += R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + pos_count +
       R"(,"type":"VEC3"},{"bufferView":1,"componentType":5123,"count":)" + idx_count + R"(,"type":"SCALAR"}],)";
  j += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":72}],)";
  j += R"("buffers":[{"byteLength":168)" + (buffer_uri.empty() ? std::string() : R"(,"uri":")" + buffer_uri + "\"") + "}]";
  j += extra + "}";
  return j;
}

std::string data_uri(const std::string& bytes) { return "data:application/octet-stream;base64," + base64(bytes); }

std::string glb(const std::string& json, const std::string& bin) {
  std::string j = json, b = bin;
  while (j.size() % 4) j += ' ';
  while (b.size() % 4) b += '\0';
  std::string out = "glTF";
  auto u32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(2), u32(static_cast<std::uint32_t>(12 + 8 + j.size() + 8 + b.size()));
  u32(static_cast<std::uint32_t>(j.size())), u32(0x4E4F534A), out += j;
  u32(static_cast<std::uint32_t>(b.size())), u32(0x004E4942), out += b;
  return out;
}

std::array<double, 2> proj_forward(const std::string& target, double lon, double lat) {
  PJ_CONTEXT* ctx = proj_context_create();
  PJ* raw = proj_create_crs_to_crs(ctx, "EPSG:4326", target.c_str(), nullptr);
  PJ* op = proj_normalize_for_visualization(ctx, raw);
  const PJ_COORD c = proj_trans(op, PJ_FWD, proj_coord(lon, lat, 0, 0));
  proj_destroy(op);
  proj_destroy(raw);
  proj_context_destroy(ctx);
  return {c.xy.x, c.xy.y};
}

/// WGS 84 geodetic -> ECEF (closed form), for making georeferenced files.
std::array<double, 3> ecef(double lon_deg, double lat_deg, double h) {
  const double a = 6378137.0, f = 1 / 298.257223563, e2 = f * (2 - f);
  const double lat = lat_deg * M_PI / 180, lon = lon_deg * M_PI / 180;
  const double n = a / std::sqrt(1 - e2 * std::sin(lat) * std::sin(lat));
  return {(n + h) * std::cos(lat) * std::cos(lon), (n + h) * std::cos(lat) * std::sin(lon), (n * (1 - e2) + h) * std::sin(lat)};
}

using test::Read;
using test::read;

/// Mean of the vertices and the z range of a mesh.
std::array<double, 4> centre(const Mesh& m) {
  double x = 0, y = 0, z0 = 1e300, z1 = -1e300;
  for (const Point3& p : m.vertices) x += p.x, y += p.y, z0 = std::min(z0, p.z), z1 = std::max(z1, p.z);
  const double n = static_cast<double>(m.vertices.size());
  return {x / n, y / n, z0, z1};
}

TEST(Gltf, CubeWithOriginLandsOnProjsAnchorWithin1cm) {
  test::TempDir tmp("groundplan_gltf_test");
  const double lon = 13.4050, lat = 52.5200;  // Berlin, UTM 33N
  ReadOptions opt;
  opt.origin = "13.4050,52.5200,34";
  for (const std::string& path : {tmp.file("cube.gltf", cube_json(data_uri(cube_buffer()))),
                                  tmp.file("cube.glb", glb(cube_json(""), cube_buffer()))}) {
    const Read r = read(path, opt);
    ASSERT_EQ(r.meshes.size(), 1u) << path << "\n" << r.all();
    EXPECT_EQ(r.meshes[0].source_id, "cube");
    EXPECT_EQ(r.meshes[0].faces.size(), 12u);
    EXPECT_EQ(r.info.working_crs.epsg, 32633);
    const auto c = centre(r.meshes[0]);
    const auto anchor = proj_forward("EPSG:32633", lon, lat);
    EXPECT_LT(std::hypot(c[0] - anchor[0], c[1] - anchor[1]), 0.01) << path;
    // y-up -> z-up: the cube's height (glTF y) is z, from the origin's 34 m.
    EXPECT_NEAR(c[2], 34.0, 1e-3);
    EXPECT_NEAR(c[3], 35.0, 1e-3);
  }
}

TEST(Gltf, NoGeoreferenceAndNoOriginIsAClearError) {
  test::TempDir tmp("groundplan_gltf_test");
  const std::string path = tmp.file("local.gltf", cube_json(data_uri(cube_buffer())));
  try {
    read(path);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("local.gltf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--origin"), std::string::npos) << e.what();
  }
}

TEST(Gltf, CesiumRtcAndEcefRootNodeAreGeoreferences) {
  test::TempDir tmp("groundplan_gltf_test");
  const double lon = -105.2728, lat = 40.0100;
  const auto c = ecef(lon, lat, 1600);
  const auto anchor = proj_forward("EPSG:32613", lon, lat);
  char center[160];
  std::snprintf(center, sizeof center, R"(,"extensionsUsed":["CESIUM_RTC"],"extensions":{"CESIUM_RTC":{"center":[%.4f,%.4f,%.4f]}})",
                c[0], c[1], c[2]);
  Read r = read(tmp.file("rtc.gltf", cube_json(data_uri(cube_buffer()), R"({"mesh":0,"name":"cube"})", center)));
  ASSERT_EQ(r.meshes.size(), 1u) << r.all();
  EXPECT_EQ(r.info.gltf.georeference, "CESIUM_RTC");
  EXPECT_EQ(r.info.working_crs.epsg, 32613);
  auto m = centre(r.meshes[0]);
  // The cube's centre is 0.5 m above the RTC centre along ECEF's axes: within a metre of the anchor.
  EXPECT_LT(std::hypot(m[0] - anchor[0], m[1] - anchor[1]), 1.0);
  EXPECT_NEAR((m[2] + m[3]) / 2, 1600, 1.0);
  // A root node whose translation puts the model in ECEF (given in glTF's y-up axes: x, z, -y).
  char node[200];
  std::snprintf(node, sizeof node, R"({"name":"ecef","translation":[%.4f,%.4f,%.4f],"children":[1]},{"mesh":0,"name":"cube"})",
                c[0], c[2], -c[1]);
  std::string json = cube_json(data_uri(cube_buffer()), node);
  r = read(tmp.file("ecef.gltf", json));
  ASSERT_EQ(r.meshes.size(), 1u) << r.all();
  EXPECT_EQ(r.info.gltf.georeference, "ECEF node transform");
  m = centre(r.meshes[0]);
  EXPECT_LT(std::hypot(m[0] - anchor[0], m[1] - anchor[1]), 1.0);
}

TEST(GltfHostile, OutOfRangeAccessorsIndicesAndBuffersAreProblemsOrErrors) {
  test::TempDir tmp("groundplan_gltf_test");
  ReadOptions opt;
  opt.origin = "13.4,52.5";
  // POSITION count 80 over a 96-byte view; indices count 360 over a 72-byte view.
  Read r = read(tmp.file("a.gltf", cube_json(data_uri(cube_buffer()), R"({"mesh":0})", "", "80")), opt);
  EXPECT_TRUE(r.meshes.empty());
  EXPECT_EQ(r.count("BAD_PRIMITIVE"), 1u) << r.all();
  r = read(tmp.file("b.gltf", cube_json(data_uri(cube_buffer()), R"({"mesh":0})", "", "8", "360")), opt);
  EXPECT_EQ(r.count("BAD_PRIMITIVE"), 1u) << r.all();
  // An index pointing past the 8 positions.
  std::string bad = cube_buffer();
  const std::uint16_t big = 999;
  std::memcpy(&bad[96 + 2 * 5], &big, 2);
  r = read(tmp.file("c.gltf", cube_json(data_uri(bad))), opt);
  EXPECT_EQ(r.count("BAD_PRIMITIVE"), 1u) << r.all();
  EXPECT_NE(r.all().find("999"), std::string::npos);
  // Mesh, node and accessor indices out of range; a node cycle.
  std::string j = cube_json(data_uri(cube_buffer()), R"({"mesh":7},{"children":[1]})");
  r = read(tmp.file("d.gltf", j), opt);
  EXPECT_TRUE(r.meshes.empty());
  EXPECT_GE(r.problems.size(), 1u);
  // A buffer outside the file's folder, absolute or climbing: refused, never read.
  tmp.file("secret.bin", cube_buffer());
  EXPECT_THROW(read(tmp.file("sub/e.gltf", cube_json("../secret.bin")), opt), InputError);
  EXPECT_THROW(read(tmp.file("sub/f.gltf", cube_json((tmp.path / "secret.bin").string())), opt), InputError);
  // Not JSON, truncated GLB.
  EXPECT_THROW(read(tmp.file("g.gltf", "{\"asset\": {"), opt), InputError);
  EXPECT_THROW(read(tmp.file("h.glb", glb(cube_json(""), cube_buffer()).substr(0, 40)), opt), InputError);
}

}  // namespace
}  // namespace groundplan::gis
