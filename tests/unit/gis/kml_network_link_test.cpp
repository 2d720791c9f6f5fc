// SPDX-License-Identifier: MIT
// KML NetworkLinks (issue 16): a 3DCityDB-style export (master .kml, NetworkLinks with Windows
// backslashes to tile .kml files, each with its COLLADA model) gives the same plans as listing the
// tiles; hostile links (.., absolute, http, cycles, a 1,000-deep chain) are bounded and reported.
#include <groundplan/gis/kml.h>
#include <groundplan/gis/pipeline.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>


#include "test_support.h"

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;


const fs::path kKorea = test::shared_data("kml-collada-korea-mago/sample-kml");  // not redistributable: ThirdParty tests

std::string network_link(const std::string& href, const std::string& id = "") {
  return "<NetworkLink" + (id.empty() ? std::string() : " id=\"" + id + "\"") +
         "><Link><href>" + href + "</href><viewRefreshMode>onRegion</viewRefreshMode></Link></NetworkLink>";
}

std::string kml_doc(const std::string& body) {
  return R"(<?xml version="1.0" encoding="UTF-8"?>)"
         "\n<kml xmlns=\"http://www.opengis.net/kml/2.2\"><Document>" + body + "</Document></kml>";
}

struct Read {
  std::size_t meshes = 0;
  std::vector<Problem> problems;
  KmlInfo info;
  std::size_t count(const std::string& code) const {
    return static_cast<std::size_t>(
        std::count_if(problems.begin(), problems.end(), [&](const Problem& p) { return p.code == code; }));
  }
};

Read read(const std::string& path, const KmlOptions& options = {}) {
  Read r;
  read_kml(path, options, [&](Mesh&&, const ModelPlacement&) { ++r.meshes; }, r.problems, r.info);
  return r;
}


/// Tiles/<i>/0/ holds one Korean sample building (its .kml and .dae); master.kml links them as
/// 3DCityDB writes them, with backslashes, through an intermediate tile index.
std::vector<std::string> make_export(const test::TempDir& tmp) {
  std::vector<std::string> tiles;
  std::string index;
  int i = 0;
  for (const char* name : {"a_bd001", "a_bd002", "a_bd003"}) {
    const fs::path dir = tmp.path / "Tiles" / std::to_string(i) / "0";
    fs::create_directories(dir);
    fs::copy_file(kKorea / (std::string(name) + ".kml"), dir / (std::string(name) + ".kml"));
    fs::copy_file(kKorea / (std::string(name) + ".dae"), dir / (std::string(name) + ".dae"));
    tiles.push_back((dir / (std::string(name) + ".kml")).string());
    index += network_link("..\\Tiles\\" + std::to_string(i) + "\\0\\" + name + ".kml", std::string("tile_") + name);
    ++i;
  }
  tmp.file("Index/index.kml", kml_doc(index));
  tmp.file("master.kml", kml_doc(network_link("Index\\index.kml", "index")));
  return tiles;
}

TEST(KmlNetworkLinkThirdParty, CityDbExportGivesTheSamePlansAsItsTiles) {
  GROUNDPLAN_SKIP_IF_MISSING(kKorea);
  test::TempDir tmp("groundplan_netlink_test");
  const std::vector<std::string> tiles = make_export(tmp);
  const Read r = read((tmp.path / "master.kml").string());
  EXPECT_EQ(r.meshes, 3u);
  EXPECT_EQ(r.info.network_links, 4u);
  EXPECT_EQ(r.info.linked_files, 4u);
  EXPECT_TRUE(r.problems.empty()) << r.problems[0].code << ": " << r.problems[0].reason;

  PipelineOptions o;
  o.inputs = {(tmp.path / "master.kml").string()};
  const PipelineResult via_links = run_pipeline(o);
  o.inputs = tiles;
  const PipelineResult listed = run_pipeline(o);
  EXPECT_EQ(via_links.buildings_read, 3u);
  EXPECT_EQ(via_links.footprints.size(), listed.footprints.size());
  ASSERT_FALSE(listed.plans.empty());
  EXPECT_EQ(test::plan_keys(via_links.plans), test::plan_keys(listed.plans));
  EXPECT_EQ(via_links.crs_name, listed.crs_name);
}

TEST(KmlNetworkLinkThirdParty, HostileLinksAreBoundedAndReported) {
  GROUNDPLAN_SKIP_IF_MISSING(kKorea);
  test::TempDir tmp("groundplan_netlink_test");
  make_export(tmp);
  tmp.file("outside.kml", kml_doc(""));
  const std::string body = network_link("..\\outside.kml") + network_link("../../etc/passwd.kml") +
                           network_link("/etc/x.kml") + network_link("C:\\x\\y.kml") +
                           network_link("http://127.0.0.1:9/x.kml") + network_link("missing.kml") +
                           network_link("a.kml") + network_link("tile.dae") + network_link("");
  tmp.file("in/a.kml", kml_doc(network_link(".\\b.kml")));
  tmp.file("in/b.kml", kml_doc(network_link("a.kml") + network_link("b.kml")));  // a cycle and a self-link
  const Read r = read(tmp.file("in/master.kml", kml_doc(body)));
  EXPECT_EQ(r.meshes, 0u);
  EXPECT_EQ(r.count("LINK_OUTSIDE_INPUT"), 4u);         // .., ../.., /etc, C:
  EXPECT_EQ(r.count("NETWORK_LINK_NOT_FOLLOWED"), 3u);  // http, .dae, no href
  EXPECT_EQ(r.count("LINK_TARGET_NOT_FOUND"), 1u);
  EXPECT_EQ(r.count("NETWORK_LINK_REPEATED"), 2u);      // b -> a, b -> b
  EXPECT_EQ(r.info.linked_files, 2u);
  for (const Problem& p : r.problems) EXPECT_TRUE(p.source_id.empty()) << p.code;  // links are not buildings

  // A chain of 1,000 files, each linking the next (every file exists, so only the depth limit stops it;
  // 10,000 behave the same, but cost seconds of disk writes here): read to the limit, then reported.
  const std::size_t n = 1000;
  fs::create_directories(tmp.path / "chain");
  for (std::size_t k = 0; k < n; ++k)
    std::ofstream(tmp.path / "chain" / (std::to_string(k) + ".kml")) << kml_doc(network_link(std::to_string(k + 1) + ".kml"));
  const Read chain = read((tmp.path / "chain" / "0.kml").string());
  KmlOptions o;
  EXPECT_EQ(chain.info.linked_files, o.max_network_link_depth);
  EXPECT_EQ(chain.count("NETWORK_LINK_TOO_DEEP"), 1u);

  // A linked tile that is not XML is that tile's problem; the others are read.
  tmp.file("Tiles/9/bad.kml", "<kml><Document>");
  const std::string master2 = tmp.file("master2.kml", kml_doc(network_link("Tiles\\9\\bad.kml") +
                                                              network_link("Index/index.kml")));
  const Read partial = read(master2);
  EXPECT_EQ(partial.meshes, 3u);
  EXPECT_EQ(partial.count("BAD_NETWORK_LINK_TARGET"), 1u);
}

}  // namespace
}  // namespace groundplan::gis
