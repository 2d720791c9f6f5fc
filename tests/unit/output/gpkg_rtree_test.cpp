// SPDX-License-Identifier: MIT
// The GeoPackage spatial index the CLI packs (driver/output/gpkg_rtree.h), on files written here through
// GDAL: every non-empty feature's box in the tree, rounded outwards to float, a tree SQLite's rtreecheck
// accepts; a geometry it cannot read leaves no half-built index behind; GDAL's own way as the fallback.
// (tests/e2e/test_gpkg_index.py compares the CLI's output with GDAL's own index on real samples.)
#include <gpkg_rtree.h>

#include <gtest/gtest.h>

#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "test_support.h"

namespace groundplan {
namespace {

struct Box {
  double minx, maxx, miny, maxy;
};

/// A new GeoPackage at `path` with layer "parts" of `n` random quads (UTM-like coordinates), one empty
/// polygon and one feature without geometry, written without a spatial index. Returns the quads' boxes by fid.
std::vector<Box> write_gpkg(const std::string& path, int n) {
  GDALDriverH drv = GDALGetDriverByName("GPKG");
  GDALDatasetH ds = GDALCreate(drv, path.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
  EXPECT_NE(ds, nullptr);
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  OSRImportFromEPSG(srs, 25832);
  char* opts[] = {const_cast<char*>("SPATIAL_INDEX=NO"), nullptr};
  OGRLayerH layer = GDALDatasetCreateLayer(ds, "parts", srs, wkbPolygon, opts);
  OSRRelease(srs);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> pos(0, 5000), size(0.001, 40);
  std::vector<Box> boxes;
  for (int i = 0; i < n; ++i) {
    const double x = 400000.123456789 + pos(rng), y = 5800000.987654321 + pos(rng), w = size(rng), h = size(rng);
    const std::string wkt = "POLYGON((" + std::to_string(x) + " " + std::to_string(y) + "," + std::to_string(x + w) +
                            " " + std::to_string(y) + "," + std::to_string(x + w) + " " + std::to_string(y + h) + "," +
                            std::to_string(x) + " " + std::to_string(y) + "))";
    OGRGeometryH g = nullptr;
    char* text = const_cast<char*>(wkt.c_str());
    OGR_G_CreateFromWkt(&text, nullptr, &g);
    OGREnvelope e;
    OGR_G_GetEnvelope(g, &e);
    boxes.push_back({e.MinX, e.MaxX, e.MinY, e.MaxY});
    OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(layer));
    OGR_F_SetGeometryDirectly(f, g);
    EXPECT_EQ(OGR_L_CreateFeature(layer, f), OGRERR_NONE);
    OGR_F_Destroy(f);
  }
  for (const char* wkt : {"POLYGON EMPTY", ""}) {  // an empty geometry and none at all: not in the index
    OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(layer));
    if (*wkt) {
      OGRGeometryH g = nullptr;
      char* text = const_cast<char*>(wkt);
      OGR_G_CreateFromWkt(&text, nullptr, &g);
      OGR_F_SetGeometryDirectly(f, g);
    }
    EXPECT_EQ(OGR_L_CreateFeature(layer, f), OGRERR_NONE);
    OGR_F_Destroy(f);
  }
  GDALClose(ds);
  return boxes;
}

/// Rows of an SQL query on the file (SQLite dialect, as GDAL passes it to SQLite), each as doubles.
std::vector<std::vector<double>> query(const std::string& path, const std::string& sql, bool update = false) {
  GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | (update ? GDAL_OF_UPDATE : 0), nullptr, nullptr, nullptr);
  EXPECT_NE(ds, nullptr);
  std::vector<std::vector<double>> rows;
  if (OGRLayerH r = GDALDatasetExecuteSQL(ds, sql.c_str(), nullptr, nullptr)) {
    OGR_L_ResetReading(r);
    while (OGRFeatureH f = OGR_L_GetNextFeature(r)) {
      std::vector<double> row;
      for (int i = 0; i < OGR_F_GetFieldCount(f); ++i) row.push_back(OGR_F_GetFieldAsDouble(f, i));
      rows.push_back(row);
      OGR_F_Destroy(f);
    }
    GDALDatasetReleaseResultSet(ds, r);
  }
  GDALClose(ds);
  return rows;
}

std::string rtreecheck(const std::string& path) {
  GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
  std::string out;
  if (OGRLayerH r = GDALDatasetExecuteSQL(ds, "SELECT rtreecheck('rtree_parts_geom')", nullptr, nullptr)) {
    if (OGRFeatureH f = OGR_L_GetNextFeature(r)) {
      out = OGR_F_GetFieldAsString(f, 0);
      OGR_F_Destroy(f);
    }
    GDALDatasetReleaseResultSet(ds, r);
  }
  GDALClose(ds);
  return out;
}

/// The index holds exactly the boxes: fid k's entry encloses box k, by less than a float step on each side.
void expect_index_holds(const std::string& path, const std::vector<Box>& boxes) {
  const auto rows = query(path, "SELECT id, minx, maxx, miny, maxy FROM rtree_parts_geom ORDER BY id");
  ASSERT_EQ(rows.size(), boxes.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k][0], static_cast<double>(k + 1));
    const Box& b = boxes[k];
    const double step = 0.2;  // x ~ 4e5: floats are 1/32 apart, and the outward step is ~0.05; y ~ 5.8e6: 0.5 apart
    EXPECT_LE(rows[k][1], b.minx);
    EXPECT_GE(rows[k][2], b.maxx);
    EXPECT_LE(rows[k][3], b.miny);
    EXPECT_GE(rows[k][4], b.maxy);
    EXPECT_LT(b.minx - rows[k][1], step);
    EXPECT_LT(rows[k][2] - b.maxx, step);
    EXPECT_LT(b.miny - rows[k][3], 1.5);
    EXPECT_LT(rows[k][4] - b.maxy, 1.5);
  }
  EXPECT_EQ(rtreecheck(path), "ok");
}

TEST(GpkgRtree, PackedIndexHoldsEveryNonEmptyBoxRoundedOutwards) {
  GDALAllRegister();
  test::TempDir dir("gpkg_rtree");
  const std::string path = (dir.path / "parts.gpkg").string();
  const std::vector<Box> boxes = write_gpkg(path, 5000);  // ~100 leaves: three levels of 51-cell nodes
  ASSERT_EQ(output::gpkg_unindexed_tables(path), std::vector<std::string>{"parts"});
  const output::RtreeBuild built = output::build_gpkg_rtrees(path, 3);
  ASSERT_EQ(built.error, "");
  EXPECT_EQ(built.tables, 1u);
  EXPECT_EQ(built.entries, boxes.size());
  EXPECT_TRUE(output::gpkg_unindexed_tables(path).empty());
  expect_index_holds(path, boxes);
  // GDAL sees the index and its extension row.
  EXPECT_EQ(query(path, "SELECT count(*) FROM gpkg_extensions WHERE extension_name = 'gpkg_rtree_index'")[0][0], 1.0);
}

// The index rows go in by INSERTs of 256 rows (gpkg_rtree.cpp, PairInserter): whole batches only, and one row.
TEST(GpkgRtree, EntriesInWholeBatchesAndASingleOne) {
  GDALAllRegister();
  for (int n : {1, 256, 512}) {
    test::TempDir dir("gpkg_rtree");
    const std::string path = (dir.path / "parts.gpkg").string();
    const std::vector<Box> boxes = write_gpkg(path, n);
    const output::RtreeBuild built = output::build_gpkg_rtrees(path, 2);
    ASSERT_EQ(built.error, "") << n;
    EXPECT_EQ(built.entries, boxes.size()) << n;
    expect_index_holds(path, boxes);
  }
}

TEST(GpkgRtree, GdalsOwnWayGivesTheSameEntries) {
  GDALAllRegister();
  test::TempDir dir("gpkg_rtree");
  const std::string a = (dir.path / "a.gpkg").string(), b = (dir.path / "b.gpkg").string();
  const std::vector<Box> boxes = write_gpkg(a, 700);
  write_gpkg(b, 700);
  output::RtreeBuild packed, gdal;
  ASSERT_TRUE(output::index_new_gpkg(a, 2, packed));
  ASSERT_TRUE(output::index_new_gpkg(b, 2, gdal, /*packed=*/false));
  EXPECT_FALSE(packed.by_gdal);
  EXPECT_TRUE(gdal.by_gdal);
  const std::string sql = "SELECT id, minx, maxx, miny, maxy FROM rtree_parts_geom ORDER BY id";
  EXPECT_EQ(query(a, sql), query(b, sql));
  expect_index_holds(b, boxes);
}

TEST(GpkgRtree, AFailureLeavesNoHalfBuiltIndex) {
  GDALAllRegister();
  test::TempDir dir("gpkg_rtree");
  auto rtree_tables = [](const std::string& path) {
    return query(path, "SELECT count(*) FROM sqlite_master WHERE name LIKE 'rtree_parts_geom%' AND type = 'table'")[0][0];
  };
  // A geometry that is not a GeoPackage blob: found while reading the boxes, before anything is written.
  const std::string bad_blob = (dir.path / "bad_blob.gpkg").string();
  write_gpkg(bad_blob, 300);
  query(bad_blob, "UPDATE parts SET geom = X'0001020304' WHERE fid = 123", /*update=*/true);
  output::RtreeBuild built = output::build_gpkg_rtrees(bad_blob, 2);
  EXPECT_NE(built.error.find("feature 123"), std::string::npos) << built.error;
  EXPECT_EQ(built.tables, 0u);
  EXPECT_EQ(output::gpkg_unindexed_tables(bad_blob), std::vector<std::string>{"parts"});
  EXPECT_EQ(rtree_tables(bad_blob), 0.0);
  // A stale trigger of the index's name: the failure comes after the tree is written, and the
  // transaction takes all of it back (the R-tree tables and the extension row too).
  const std::string stale = (dir.path / "stale_trigger.gpkg").string();
  write_gpkg(stale, 300);
  query(stale, "CREATE TRIGGER rtree_parts_geom_delete AFTER DELETE ON parts BEGIN SELECT 1; END", /*update=*/true);
  built = output::build_gpkg_rtrees(stale, 2);
  EXPECT_NE(built.error.find("rtree_parts_geom_delete"), std::string::npos) << built.error;
  EXPECT_EQ(built.tables, 0u);
  EXPECT_EQ(rtree_tables(stale), 0.0);
  EXPECT_EQ(query(stale, "SELECT count(*) FROM sqlite_master WHERE name = 'gpkg_extensions'")[0][0], 0.0);
}

}  // namespace
}  // namespace groundplan
