// SPDX-License-Identifier: MIT
// Reading on every core (issue 14): a CityGML file read in chunks side by side, and a folder of files
// read side by side, give exactly what reading everything one building after the other gives: the
// same meshes, footprints, problems (in the same order, with the same words) and plans, bit for bit.
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/citygml_chunks.h>
#include <groundplan/gis/pipeline.h>

#include <gtest/gtest.h>

#include <cpl_vsi.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.h"

namespace groundplan {
namespace {

namespace fs = std::filesystem;

/// Every CityGML file of the real samples in the repository or of the third-party ones, sorted.
std::vector<std::string> real_citygml_files(test::Samples which) {
  return test::real_sample_files(which, {".gml", ".citygml"});
}

/// A lower bound that depends on which samples a test runs over.
std::size_t least(test::Samples which, std::size_t in_repo, std::size_t third_party) {
  return which == test::Samples::InRepo ? in_repo : third_party;
}

std::string describe(const Mesh& m) {
  std::string s = m.source_id + "|" + m.parent_id + "|" + m.name + "|" + std::to_string(m.faces.size()) + "|";
  for (const Point3& p : m.vertices) s.append(reinterpret_cast<const char*>(&p), sizeof p);
  for (const auto i : m.indices) s.append(reinterpret_cast<const char*>(&i), sizeof i);
  for (const MeshFace& f : m.faces) s += std::to_string(static_cast<int>(f.kind)) + "/" + std::to_string(f.lod) + ",";
  return s;
}

std::string describe(const Problem& p) { return p.source_id + "|" + p.file + "|" + p.stage + "|" + p.code + "|" + p.reason; }

struct Reading {
  std::vector<std::string> meshes;
  std::vector<std::string> problems;
};

Reading read_whole(const std::string& path) {
  Reading r;
  std::vector<Problem> problems;
  gis::SourceInfo info;
  gis::read_citygml(path, {}, [&](Mesh&& m) { r.meshes.push_back(describe(m)); }, problems, info);
  for (const Problem& p : problems) r.problems.push_back(describe(p));
  return r;
}

/// Counts the start tags of the root's members: what a cut at every member must give as chunks.
std::size_t count_members(const std::string& path) {
  VSILFILE* f = VSIFOpenL(path.c_str(), "rb");
  std::string text;
  char buf[1 << 16];
  for (std::size_t n; (n = VSIFReadL(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  VSIFCloseL(f);
  std::size_t count = 0;
  for (const char* name : {"cityObjectMember", "featureMember"})
    for (std::size_t p = 0; (p = text.find(name, p)) != std::string::npos; p += std::strlen(name)) {
      const char before = p > 0 ? text[p - 1] : ' ';
      const char after = p + std::strlen(name) < text.size() ? text[p + std::strlen(name)] : ' ';
      const bool start = (before == '<' || (before == ':' && text.rfind('<', p) != std::string::npos &&
                                            text[text.rfind('<', p) + 1] != '/')) &&
                         (after == '>' || after == ' ' || after == '\n' || after == '\r' || after == '\t');
      count += start;
    }
  return count;
}

// Once over the samples in the repository, once over the third-party ones (ThirdParty/..., skipped without them).
class ChunkedCityGmlSamples : public ::testing::TestWithParam<test::Samples> {};
INSTANTIATE_TEST_SUITE_P(InRepo, ChunkedCityGmlSamples, ::testing::Values(test::Samples::InRepo));
INSTANTIATE_TEST_SUITE_P(ThirdParty, ChunkedCityGmlSamples, ::testing::Values(test::Samples::ThirdParty));

TEST_P(ChunkedCityGmlSamples, CutAtEveryMemberReadsEveryBuildingOnceAsTheWholeFileDoes) {
  GROUNDPLAN_SKIP_IF_NO_SAMPLES(GetParam());
  std::size_t files_chunked = 0, chunks = 0;
  for (const std::string& path : real_citygml_files(GetParam())) {
    SCOPED_TRACE(path);
    const gis::CityGmlChunkPlan plan = gis::plan_citygml_chunks(path, 1, 1);  // a cut at every member
    if (!plan.why_not.empty()) continue;
    // Ranges tile the file from the first member to its end, one member each.
    ASSERT_EQ(plan.ranges.back().second, plan.file_bytes);
    for (std::size_t k = 1; k < plan.ranges.size(); ++k) ASSERT_EQ(plan.ranges[k].first, plan.ranges[k - 1].second);
    EXPECT_EQ(plan.ranges.size(), count_members(path));

    std::vector<gis::SourceInfo> infos(plan.ranges.size());
    std::vector<gis::CityGmlChunkWatch> watches(plan.ranges.size());
    Reading chunked;
    std::vector<Problem> problems;
    for (std::size_t k = 0; k < plan.ranges.size(); ++k)
      gis::read_citygml_chunk(path, plan, k, {}, [&](Mesh&& m) { chunked.meshes.push_back(describe(m)); }, problems,
                              infos[k], watches[k]);
    gis::SourceInfo merged;
    const std::string why = gis::merge_citygml_chunks(path, plan, infos, watches, merged, problems);
    if (!why.empty()) continue;  // the pipeline reads such a file whole (ChunkedPipeline checks that too)
    for (const Problem& p : problems) chunked.problems.push_back(describe(p));
    const Reading whole = read_whole(path);
    ASSERT_EQ(chunked.meshes.size(), whole.meshes.size()) << "a building lost or doubled";
    for (std::size_t i = 0; i < whole.meshes.size(); ++i) ASSERT_EQ(chunked.meshes[i], whole.meshes[i]) << "mesh " << i;
    EXPECT_EQ(chunked.problems, whole.problems);
    ++files_chunked;
    chunks += plan.ranges.size();
  }
  // Every real file of more than one member is cut (2,266 chunks on 2026-11-24's samples: 7 files and 1,315 chunks
  // in the repository, 19 files and 951 chunks of the third-party ones).
  EXPECT_GE(files_chunked, least(GetParam(), 7, 18));
  EXPECT_GE(chunks, least(GetParam(), 1150, 850));
}

TEST(ChunkedCityGml, ACutInsideAMemberMakesTheChunkFailNotReadOtherwise) {
  // A comment holding a member start tag, and a nested member: cuts found there must not be trusted.
  const std::string doc =
      "<?xml version=\"1.0\"?>\n<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\" "
      "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\">\n"
      "<core:cityObjectMember><bldg:Building gml:id=\"a\"/></core:cityObjectMember>\n"
      "<!-- <core:cityObjectMember> in a comment -->\n"
      "<core:cityObjectMember><grp><core:cityObjectMember><bldg:Building gml:id=\"b\"/></core:cityObjectMember></grp>"
      "</core:cityObjectMember>\n</core:CityModel>\n";
  const std::string path = "/vsimem/chunks_inside_member.gml";
  VSILFILE* f = VSIFileFromMemBuffer(path.c_str(), reinterpret_cast<GByte*>(const_cast<char*>(doc.data())),
                                     doc.size(), FALSE);
  VSIFCloseL(f);
  const gis::CityGmlChunkPlan plan = gis::plan_citygml_chunks(path, 1, 1);
  ASSERT_TRUE(plan.why_not.empty()) << plan.why_not;
  ASSERT_EQ(plan.ranges.size(), 4u);  // at both real members, in the comment, and at the nested member
  std::size_t failed = 0;
  for (std::size_t k = 0; k < plan.ranges.size(); ++k) {
    std::vector<Problem> problems;
    gis::SourceInfo info;
    gis::CityGmlChunkWatch watch;
    try {
      gis::read_citygml_chunk(path, plan, k, {}, [](Mesh&&) {}, problems, info, watch);
    } catch (const InputError&) {
      ++failed;
    }
  }
  VSIUnlink(path.c_str());
  // Each wrong cut fails the chunks on both sides of it: the one ending inside the comment or the outer
  // member, and the one starting there (a closing tag or comment end it never opened).
  EXPECT_EQ(failed, 4u);
}

TEST(ChunkedCityGml, CutsAreFoundPastLongHeadsAndAcrossTheReadWindows) {
  // The planner reads the head, and around each cut, a few KiB at a time: a first member far into the
  // file (a 200 KiB envelope comment) and members far apart, with their start tags falling across every
  // byte offset of the planner's read windows, must still give a cut at every member.
  const std::string head =
      "<?xml version=\"1.0\"?>\n<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\" "
      "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\">\n<!--" +
      std::string(200 << 10, '.') + "-->\n";
  std::string doc = head;
  std::vector<std::uint64_t> starts;
  for (int i = 0; i < 100; ++i) {
    starts.push_back(doc.size());
    // Members of 64 KiB - 200 + 7i bytes: the next start tag, searched from just after a cut, walks
    // across the ends of the planner's 64 KiB windows (with and without their overlap).
    doc += "<core:cityObjectMember><bldg:Building gml:id=\"b" + std::to_string(i) + "\"><!--" +
           std::string((64u << 10) - 200u + 7u * static_cast<unsigned>(i), ' ') +
           "--></bldg:Building></core:cityObjectMember>\n";
  }
  doc += "</core:CityModel>\n";
  const std::string path = "/vsimem/chunks_long_head.gml";
  VSILFILE* f = VSIFileFromMemBuffer(path.c_str(), reinterpret_cast<GByte*>(doc.data()), doc.size(), FALSE);
  VSIFCloseL(f);
  const gis::CityGmlChunkPlan plan = gis::plan_citygml_chunks(path, 1, 1);
  VSIUnlink(path.c_str());
  ASSERT_TRUE(plan.why_not.empty()) << plan.why_not;
  EXPECT_EQ(plan.head.size(), head.size());
  std::vector<std::uint64_t> cuts;
  for (const auto& r : plan.ranges) cuts.push_back(r.first);
  EXPECT_EQ(cuts, starts);
}

// --- the whole pipeline -----------------------------------------------------------------------

void expect_same(const gis::PipelineResult& a, const gis::PipelineResult& b) {
  EXPECT_EQ(a.buildings_read, b.buildings_read);
  EXPECT_EQ(a.buildings_dropped, b.buildings_dropped);
  EXPECT_EQ(a.crs_wkt, b.crs_wkt);
  ASSERT_EQ(a.footprints.size(), b.footprints.size());
  for (std::size_t i = 0; i < a.footprints.size(); ++i) {
    const Footprint &x = a.footprints[i], &y = b.footprints[i];
    ASSERT_EQ(x.source_id, y.source_id) << i;
    EXPECT_EQ(x.source_file, y.source_file);
    EXPECT_EQ(x.method, y.method);
    EXPECT_EQ(x.min_z, y.min_z);
    EXPECT_EQ(x.max_z, y.max_z);
    ASSERT_EQ(x.polygons.size(), y.polygons.size());
    for (std::size_t p = 0; p < x.polygons.size(); ++p) {
      EXPECT_EQ(x.polygons[p].outer, y.polygons[p].outer) << x.source_id;
      EXPECT_EQ(x.polygons[p].holes, y.polygons[p].holes) << x.source_id;
    }
  }
  ASSERT_EQ(a.problems.size(), b.problems.size());
  for (std::size_t i = 0; i < a.problems.size(); ++i) EXPECT_EQ(describe(a.problems[i]), describe(b.problems[i])) << i;
  ASSERT_EQ(a.plans.size(), b.plans.size());
  for (std::size_t i = 0; i < a.plans.size(); ++i) {
    EXPECT_EQ(a.plans[i].polygon.outer, b.plans[i].polygon.outer) << i;
    EXPECT_EQ(a.plans[i].polygon.holes, b.plans[i].polygon.holes) << i;
    EXPECT_EQ(a.plans[i].members, b.plans[i].members) << i;
  }
}

gis::PipelineResult run(const std::string& input, int threads, std::int64_t chunk_bytes) {
  gis::PipelineOptions o;
  o.inputs = {input};
  o.threads = threads;
  o.read_chunk_bytes = chunk_bytes;
  return gis::run_pipeline(o);
}

class ChunkedPipelineSamples : public ::testing::TestWithParam<test::Samples> {};
INSTANTIATE_TEST_SUITE_P(InRepo, ChunkedPipelineSamples, ::testing::Values(test::Samples::InRepo));
INSTANTIATE_TEST_SUITE_P(ThirdParty, ChunkedPipelineSamples, ::testing::Values(test::Samples::ThirdParty));

TEST_P(ChunkedPipelineSamples, EveryRealFileCutInSmallChunksGivesTheOneThreadResult) {
  GROUNDPLAN_SKIP_IF_NO_SAMPLES(GetParam());
  // Chunks of 16 KiB (a few members each): every cut position of the reader test above, in the pipeline
  // (georeference, footprints, problems in order, plans), costs minutes on 2 cores when cut at every member.
  std::size_t chunked = 0;
  for (const std::string& path : real_citygml_files(GetParam())) {
    SCOPED_TRACE(path);
    gis::PipelineResult serial, parallel;
    try {
      serial = run(path, 1, -1);
    } catch (const Error& e) {  // a sample that is no input on its own (no building): the same both ways
      EXPECT_THROW(run(path, 3, 16 << 10), Error);
      continue;
    }
    parallel = run(path, 3, 16 << 10);
    EXPECT_EQ(serial.reading.files_chunked, 0u);
    chunked += parallel.reading.files_chunked;
    expect_same(serial, parallel);
  }
  EXPECT_GE(chunked, least(GetParam(), 4, 4));  // 7 files chunked of each on 2026-11-27
}

/// A folder read one file at a time, files side by side, and files side by side cut in chunks: the same result.
void expect_folder_gives_the_one_thread_result(const std::string& folder) {
  SCOPED_TRACE(folder);
  const gis::PipelineResult serial = run(folder, 1, -1);
  const gis::PipelineResult files_side_by_side = run(folder, 4, -1);
  const gis::PipelineResult and_chunks = run(folder, 4, 64 << 10);
  EXPECT_EQ(files_side_by_side.reading.threads, 4u);
  if (folder.find("fzkhaus") == std::string::npos) EXPECT_GT(and_chunks.reading.files_chunked, 0u);
  expect_same(serial, files_side_by_side);
  expect_same(serial, and_chunks);
}

TEST(ChunkedPipeline, FoldersOfTilesGiveTheOneThreadResult) {
  for (const std::string& folder : {test::shared_data("citygml1-niedersachsen-lod1-4tiles"),
                                    test::shared_data("citygml2-plateau-japan-lod1")})
    expect_folder_gives_the_one_thread_result(folder);
}

TEST(ChunkedPipelineThirdParty, FolderOfSingleBuildingsGivesTheOneThreadResult) {
  // CityGML 2 and 3, LoD1-3, files of one building: read side by side, none cut. Only part of it is redistributable.
  const std::string folder = test::thirdparty_data("citygml-fzkhaus-denhaag-misc");
  GROUNDPLAN_SKIP_IF_MISSING(folder);
  expect_folder_gives_the_one_thread_result(folder);
}

}  // namespace
}  // namespace groundplan

namespace groundplan {
namespace {

/// A CityGML 2.0 file of `members` (each a cityObjectMember's content), in EPSG:25832.
std::string citygml_doc(const std::vector<std::string>& members) {
  std::string doc =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\" "
      "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\" "
      "xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n";
  for (const std::string& m : members) doc += "<core:cityObjectMember>" + m + "</core:cityObjectMember>\n";
  return doc + "</core:CityModel>\n";
}

/// A building with one GroundSurface square at (x, y); `poly_id` names its polygon ("" = none).
std::string building(const std::string& id, double x, double y, const std::string& poly_id = "") {
  auto c = [](double v) { return std::to_string(v); };
  const std::string ring = c(x) + " " + c(y) + " 0 " + c(x + 10) + " " + c(y) + " 0 " + c(x + 10) + " " + c(y + 10) +
                           " 0 " + c(x) + " " + c(y + 10) + " 0 " + c(x) + " " + c(y) + " 0";
  return "<bldg:Building" + (id.empty() ? std::string() : " gml:id=\"" + id + "\"") +
         "><bldg:boundedBy><bldg:GroundSurface><bldg:lod2MultiSurface><gml:MultiSurface srsName=\"EPSG:25832\" "
         "srsDimension=\"3\"><gml:surfaceMember><gml:Polygon" +
         (poly_id.empty() ? std::string() : " gml:id=\"" + poly_id + "\"") +
         "><gml:exterior><gml:LinearRing><gml:posList>" + ring +
         "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember></gml:MultiSurface>"
         "</bldg:lod2MultiSurface></bldg:GroundSurface></bldg:boundedBy></bldg:Building>";
}

/// Runs `doc` serially and cut at every member; both must agree, and the cut run must have read it whole.
void expect_read_whole_and_same(const std::string& doc, const std::string& why_fragment) {
  const std::string path = "/vsimem/chunk_fallback.gml";
  VSILFILE* f = VSIFileFromMemBuffer(path.c_str(), reinterpret_cast<GByte*>(const_cast<char*>(doc.data())),
                                     doc.size(), FALSE);
  VSIFCloseL(f);
  const gis::PipelineResult serial = run(path, 1, -1);
  const gis::PipelineResult cut = run(path, 3, 1);
  VSIUnlink(path.c_str());
  EXPECT_EQ(cut.reading.files_chunked, 0u);
  ASSERT_EQ(cut.reading.read_whole.size(), 1u);
  EXPECT_NE(cut.reading.read_whole[0].second.find(why_fragment), std::string::npos) << cut.reading.read_whole[0].second;
  expect_same(serial, cut);
}

TEST(ChunkedPipeline, StateAcrossMembersMakesTheFileBeReadWhole) {
  std::vector<std::string> base;
  for (int i = 0; i < 6; ++i) base.push_back(building("b" + std::to_string(i), 400000 + 30 * i, 5800000));
  {
    SCOPED_TRACE("an id in two chunks: DUPLICATE_ID is said by the whole-file reader only");
    std::vector<std::string> m = base;
    m[4] = building("b1", 400500, 5800000);
    expect_read_whole_and_same(citygml_doc(m), "two chunks");
  }
  {
    SCOPED_TRACE("an xlink to another building's polygon");
    std::vector<std::string> m = base;
    m[1] = building("b1", 400030, 5800000, "shared-poly");
    m[4] = "<bldg:Building gml:id=\"b4\"><bldg:lod1MultiSurface xlink:href=\"#shared-poly\"/></bldg:Building>";
    expect_read_whole_and_same(citygml_doc(m), "xlinks between buildings");
  }
  {
    SCOPED_TRACE("a building without gml:id is named by its line");
    std::vector<std::string> m = base;
    m[3] = building("", 400090, 5800000);
    expect_read_whole_and_same(citygml_doc(m), "without gml:id");
  }
  {
    SCOPED_TRACE("nothing across members: cut");
    const std::string doc = citygml_doc(base);
    const std::string path = "/vsimem/chunk_ok.gml";
    VSILFILE* f = VSIFileFromMemBuffer(path.c_str(), reinterpret_cast<GByte*>(const_cast<char*>(doc.data())),
                                       doc.size(), FALSE);
    VSIFCloseL(f);
    const gis::PipelineResult serial = run(path, 1, -1), cut = run(path, 3, 1);
    VSIUnlink(path.c_str());
    EXPECT_EQ(cut.reading.chunks, 6u);
    EXPECT_EQ(serial.footprints.size(), 6u);
    expect_same(serial, cut);
  }
}

}  // namespace
}  // namespace groundplan
