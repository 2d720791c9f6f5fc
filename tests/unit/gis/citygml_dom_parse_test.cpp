// SPDX-License-Identifier: MIT
// The CityGML reader's in-memory path (issue 14, gis/src/xml/dom_events.h): pugixml's tree walked into
// the events expat gives must read every document exactly as expat does (meshes bit for bit, problems
// word for word, line numbers in ids and messages included), and every document pugixml would read
// otherwise must go to expat.
#include <groundplan/error.h>
#include <groundplan/gis/citygml.h>

#include <gtest/gtest.h>

#include "test_support.h"
#include "xml/dom_events.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;

struct Outcome {
  std::vector<std::string> meshes;    // every field, doubles by their bits
  std::vector<std::string> problems;  // every field
  std::string error;                  // the InputError's message, if one was thrown
  SourceInfo info;
};

std::string bits(double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, 8);
  return std::to_string(u);
}

std::string describe(const Mesh& m) {
  std::ostringstream s;
  s << m.source_id << '|' << m.parent_id << '|' << m.source_file << '|' << m.name << '|' << bits(m.measured_height);
  for (const Point3& p : m.vertices) s << ' ' << bits(p.x) << ',' << bits(p.y) << ',' << bits(p.z);
  s << " /";
  for (auto i : m.indices) s << ' ' << i;
  s << " /";
  for (auto o : m.ring_offsets) s << ' ' << o;
  s << " /";
  for (const MeshFace& f : m.faces)
    s << ' ' << f.first_ring << ':' << f.ring_count << ':' << static_cast<int>(f.kind) << ':' << int{f.lod};
  return s.str();
}

template <class Read>
Outcome outcome(Read&& read) {
  Outcome o;
  std::vector<Problem> problems;
  try {
    read([&](Mesh&& m) { o.meshes.push_back(describe(m)); }, problems, o.info);
  } catch (const InputError& e) {
    o.error = e.what();
  }
  for (const Problem& p : problems)
    o.problems.push_back(p.source_id + " | " + p.file + " | " + p.stage + " | " + p.code + " | " + p.reason);
  return o;
}

CityGmlOptions with_dom(bool on) {
  CityGmlOptions o;
  if (!on) o.dom_max_bytes = 0;
  return o;
}

Outcome read_buffer(const std::string& xml, bool dom) {
  const CityGmlOptions opt = with_dom(dom);
  return outcome([&](const MeshCallback& cb, std::vector<Problem>& p, SourceInfo& i) {
    read_citygml_buffer(xml, "inline.gml", opt, cb, p, i);
  });
}

Outcome read_path(const std::string& path, bool dom) {
  const CityGmlOptions opt = with_dom(dom);
  return outcome([&](const MeshCallback& cb, std::vector<Problem>& p, SourceInfo& i) {
    read_citygml(path, opt, cb, p, i);
  });
}

void expect_same(const Outcome& dom, const Outcome& expat, const std::string& what) {
  EXPECT_EQ(dom.error, expat.error) << what;
  EXPECT_EQ(dom.meshes, expat.meshes) << what;
  EXPECT_EQ(dom.problems, expat.problems) << what;
  EXPECT_EQ(dom.info.buildings, expat.info.buildings) << what;
  EXPECT_EQ(dom.info.srs_name, expat.info.srs_name) << what;
  EXPECT_EQ(dom.info.citygml_version, expat.info.citygml_version) << what;
  EXPECT_EQ(dom.info.bytes, expat.info.bytes) << what;
}

std::vector<std::string> citygml_files(test::Samples which) {
  std::vector<std::string> files;
  for (const std::string& f : test::real_sample_files(which, {".gml", ".xml", ".citygml"})) {
    std::ifstream in(f, std::ios::binary);
    std::string head(4096, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    if (looks_like_citygml(head)) files.push_back(f);
  }
  return files;
}

// Once over the samples in the repository, once over the third-party ones (ThirdParty/..., skipped without them).
class CityGmlInMemorySamples : public ::testing::TestWithParam<test::Samples> {};
INSTANTIATE_TEST_SUITE_P(InRepo, CityGmlInMemorySamples, ::testing::Values(test::Samples::InRepo));
INSTANTIATE_TEST_SUITE_P(ThirdParty, CityGmlInMemorySamples, ::testing::Values(test::Samples::ThirdParty));

TEST_P(CityGmlInMemorySamples, EveryRealSampleReadsAsExpatReadsIt) {
  GROUNDPLAN_SKIP_IF_NO_SAMPLES(GetParam());
  const std::vector<std::string> files = citygml_files(GetParam());
  ASSERT_GE(files.size(), 10u) << "the real samples are missing";
  std::size_t in_memory = 0, meshes = 0;
  for (const std::string& f : files) {
    const Outcome dom = read_path(f, true), expat = read_path(f, false);
    expect_same(dom, expat, f);
    EXPECT_EQ(expat.info.bytes_streamed, expat.info.bytes) << f;
    if (dom.info.bytes_streamed == 0 && dom.info.bytes > 0) ++in_memory;
    else ADD_FAILURE() << f << " was not parsed in memory: " << dom.info.streamed_why;
    meshes += dom.meshes.size();
  }
  EXPECT_GT(meshes, 500u);
  EXPECT_EQ(in_memory, files.size());
}

// Documents whose line numbers reach the output (buildings without gml:id, polygons without one with a
// defect) in every layout that moves lines: CR LF and CR endings, tags over several lines, comments,
// CDATA, empty-element tags, a BOM, namespaces declared deeper, entity and character references.
std::string city(const std::string& body, const std::string& eol = "\n") {
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>" + eol +
                  "<core:CityModel xmlns:core=\"http://www.opengis.net/citygml/2.0\"" + eol +
                  "   xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\"" +
                  eol + "   xmlns:xlink=\"http://www.w3.org/1999/xlink\">" + eol + body + eol + "</core:CityModel>" + eol;
  return s;
}

std::string ground(const std::string& polygon, const std::string& eol = "\n") {
  return "<bldg:boundedBy>" + eol + "<bldg:GroundSurface><bldg:lod2MultiSurface><gml:MultiSurface>" + eol +
         "<gml:surfaceMember>" + polygon + "</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface>" + eol +
         "</bldg:GroundSurface></bldg:boundedBy>";
}

const std::string kSquare = "0 0 0 10 0 0 10 10 0 0 10 0 0 0 0";

std::vector<std::pair<std::string, std::string>> tricky_documents() {
  std::vector<std::pair<std::string, std::string>> docs;
  for (const std::string eol : {"\n", "\r\n", "\r"}) {
    const std::string name = eol == "\n" ? "LF" : eol == "\r\n" ? "CRLF" : "CR";
    const std::string poly_ok = "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>" + kSquare +
                                "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>";
    // A defect found at the posList's end tag, on a later line than its start (multi-line coordinates).
    const std::string poly_bad = "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0" + eol + "10 0 0" +
                                 eol + "oops</gml:posList>" + eol + "</gml:LinearRing></gml:exterior></gml:Polygon>";
    // A defect found at the Polygon's end tag, after comments and whitespace.
    const std::string poly_no_exterior = "<gml:Polygon>" + eol + "<!-- a comment" + eol + " over lines -->" + eol +
                                         "<?pi x?>" + eol + "  </gml:Polygon>";
    // Too few points, found at the LinearRing's end, after an empty element.
    const std::string poly_few = "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 1 1 0</gml:posList>" +
                                 eol + "<gml:empty/>" + eol + "</gml:LinearRing></gml:exterior></gml:Polygon>";
    const std::string b1 = "<core:cityObjectMember><bldg:Building" + eol + "  >" + ground(poly_ok, eol) +
                           "</bldg:Building></core:cityObjectMember>";
    const std::string b2 = "<core:cityObjectMember>" + eol + "<bldg:Building><gml:name>A &amp; B &#x42;<![CDATA[<c>]]>" +
                           "</gml:name>" + ground(poly_bad, eol) + ground(poly_ok, eol) +
                           "</bldg:Building></core:cityObjectMember>";
    const std::string b3 = "<core:cityObjectMember><bldg:Building>" + ground(poly_no_exterior, eol) +
                           ground(poly_few, eol) + ground(poly_ok, eol) + "</bldg:Building></core:cityObjectMember>";
    // CDATA and a comment inside the coordinates; a namespace declared on an inner element.
    const std::string b4 = "<core:cityObjectMember><b:Building xmlns:b=\"http://www.opengis.net/citygml/building/2.0\">" +
                           eol + "<b:boundedBy><b:GroundSurface><b:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>" +
                           "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0 <!-- c --> 10 0 0" + eol +
                           "<![CDATA[10 10 0]]> 0 10 0 0 0 0</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>" +
                           "</gml:surfaceMember></gml:MultiSurface></b:lod2MultiSurface></b:GroundSurface></b:boundedBy>" +
                           "</b:Building></core:cityObjectMember>";
    // An empty posList (whitespace only) and an empty-element Building.
    const std::string b5 = "<core:cityObjectMember><bldg:Building/></core:cityObjectMember>" + eol +
                           "<core:cityObjectMember><bldg:Building>" +
                           ground("<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>  " + eol +
                                      " </gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>",
                                  eol) +
                           "</bldg:Building></core:cityObjectMember>";
    docs.emplace_back(name + " layouts", city(b1 + eol + b2 + eol + eol + b3 + eol + b4 + eol + b5, eol));
    docs.emplace_back(name + " with a BOM", "\xEF\xBB\xBF" + city(b3 + eol + b1, eol));
  }
  // A default namespace (CityGML 3.0 style) and attributes in no namespace.
  docs.emplace_back("default namespace",
                    "<CityModel xmlns=\"http://www.opengis.net/citygml/3.0\" xmlns:gml=\"http://www.opengis.net/gml/3.2\""
                    " xmlns:bldg=\"http://www.opengis.net/citygml/building/3.0\">\n<cityObjectMember>\n<bldg:Building>"
                    "<boundary><bldg:GroundSurface><lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>"
                    "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">" +
                        kSquare + "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>"
                                  "</gml:MultiSurface></lod2MultiSurface></bldg:GroundSurface></boundary>"
                                  "<boundary><bldg:GroundSurface><lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>"
                                  "<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 x\n</gml:posList>"
                                  "</gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>"
                                  "</gml:MultiSurface></lod2MultiSurface></bldg:GroundSurface></boundary>"
                                  "</bldg:Building>\n</cityObjectMember>\n</CityModel>\n");
  return docs;
}

TEST(CityGmlInMemory, LineNumbersAndTextMatchExpatInEveryLayout) {
  for (const auto& [what, xml] : tricky_documents()) {
    const Outcome dom = read_buffer(xml, true), expat = read_buffer(xml, false);
    expect_same(dom, expat, what);
    EXPECT_EQ(dom.info.bytes_streamed, 0u) << what << ": " << dom.info.streamed_why;
    EXPECT_FALSE(dom.meshes.empty()) << what;
    // The layouts must put line numbers into the output, or this test would not test them.
    bool line_in_id = false, line_in_message = false;
    for (const std::string& m : dom.meshes) line_in_id |= m.find("@line") != std::string::npos;
    for (const std::string& p : dom.problems) {
      line_in_id |= p.find("@line") != std::string::npos;
      line_in_message |= p.find("at line ") != std::string::npos;
    }
    EXPECT_TRUE(line_in_id) << what;
    EXPECT_TRUE(line_in_message) << what;
  }
}

// Documents pugixml would read otherwise: each must be left to expat (bytes_streamed, a reason) and so
// read exactly as expat reads it.
TEST(CityGmlInMemory, DocumentsPugixmlWouldReadOtherwiseGoToExpat) {
  const std::string body = "<core:cityObjectMember><bldg:Building gml:id=\"b\">" +
                           ground("<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>" + kSquare +
                                  "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>") +
                           "</bldg:Building></core:cityObjectMember>";
  const std::string ok = city(body);
  const std::size_t root = ok.find("<core:CityModel");
  std::vector<std::pair<std::string, std::string>> docs = {
      {"internal DTD with an entity", ok.substr(0, root) + "<!DOCTYPE x [<!ENTITY e \"b\">]>\n" + ok.substr(root)},
      {"undefined entity", city("<!-- &nbsp; -->" + body)},
      {"entity in a name", city(body + "<gml:name>&e;</gml:name>")},
      {"character reference to NUL", city("<gml:name>&#0;</gml:name>" + body)},
      {"Latin-1 declared", "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>" + ok.substr(ok.find('\n')) },
      {"malformed declaration (fuzz_citygml)", "<?xml versin=\"o.10\" encoding=\"UTF-8\"?>" + ok.substr(ok.find('\n'))},
      {"declaration without version", "<?xml encoding=\"UTF-8\"?>" + ok.substr(ok.find('\n'))},
      {"declaration with junk", "<?xml version=\"1.0\" junk?>" + ok.substr(ok.find('\n'))},
      {"invalid UTF-8", city(body + "<gml:name>\xC3\x28</gml:name>")},
      {"overlong UTF-8", city(body + "<gml:name>\xC0\xAF</gml:name>")},
      {"control character", city(body + "<gml:name>\x01</gml:name>")},
      {"junk after the root", ok + "junk"},
      {"second root", ok + "<x/>"},
      {"duplicate attribute", city("<core:cityObjectMember><bldg:Building gml:id=\"a\" gml:id=\"b\"/></core:cityObjectMember>" + body)},
      {"duplicate attribute through two prefixes",
       city("<core:cityObjectMember><bldg:Building xmlns:g2=\"http://www.opengis.net/gml\" gml:id=\"a\" g2:id=\"b\"/>"
            "</core:cityObjectMember>" + body)},
      {"unbound prefix", city(body + "<nope:Thing/>")},
      {"empty prefix binding", city("<x xmlns:p=\"\"/>" + body)},
      {"'<' in a namespace declaration (fuzz_citygml)", city("<x xmlns:p=\"a<b\"/>" + body)},
      {"'<' in an attribute", city("<x a=\"a<b\"/>" + body)},
      {"a space in a namespace URI (fuzz_citygml)", city("<x xmlns:p=\"a b\"/>" + body)},
      {"a prefix with a colon (fuzz_citygml)", city("<x xmlns:p:q=\"a\"/>" + body)},
      {"a prefix declared twice", city("<x xmlns:p=\"a\" xmlns:p=\"b\"/>" + body)},
      {"a non-ASCII name", city("<x\xC3\x97y/>" + body)},
      {"'--' in a comment", city("<!-- a -- b -->" + body)},
      {"a comment ending in '-'", city(body + "<!-- a --->")},
      {"a PI named XML", city(body + "<?XML x?>")},
      {"a local name starting with '.' (fuzz_citygml)", city("<x xlink:.ref=\"a\"/>" + body)},
      {"an element name with two colons", city("<gml:a:b/>" + body)},
      {"an element name with an empty prefix", city("<:a/>" + body)},
      {"an element name with an empty local part", city("<gml:/>" + body)},
      {"an element's local name starting with a digit", city("<gml:1a/>" + body)},
      {"an element's local name starting with a colon", city("<gml::a/>" + body)},
      {"an attribute name with two colons", city("<x gml:a:b=\"1\"/>" + body)},
      {"an attribute name with an empty local part", city("<x gml:=\"1\"/>" + body)},
      {"an attribute's local name starting with '-'", city("<x gml:-a=\"1\"/>" + body)},
      {"spaces before the declaration (fuzz_citygml)", "   " + ok},
      {"coordinates holding elements (fuzz_citygml)",
       city("<core:cityObjectMember><bldg:Building gml:id=\"c\">" +
            ground("<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>0 0 0  <x/>\n  <y/>\n 1 1 0"
                   "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>") +
            "</bldg:Building></core:cityObjectMember>" + body)},
      {"truncated", ok.substr(0, ok.size() / 2 + 40)},
      {"mismatched end tag", city(body + "<a></b>")},
      {"empty", ""},
      {"text only", "hello"},
      {"UTF-16 BOM", "\xFF\xFE<\0a\0/\0>\0"},
  };
  for (const auto& [what, xml] : docs) {
    const Outcome dom = read_buffer(xml, true), expat = read_buffer(xml, false);
    expect_same(dom, expat, what);
    EXPECT_EQ(dom.info.bytes_streamed, dom.info.bytes) << what;
    EXPECT_FALSE(dom.info.streamed_why.empty()) << what;
  }
  // The document they were made from is read in memory.
  const Outcome dom = read_buffer(ok, true);
  EXPECT_EQ(dom.info.bytes_streamed, 0u) << dom.info.streamed_why;
  EXPECT_EQ(dom.meshes.size(), 1u);
}

TEST(CityGmlInMemory, LargerDocumentsAreStreamedAndSaySo) {
  const std::string xml = city("<core:cityObjectMember><bldg:Building gml:id=\"b\">" +
                               ground("<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>" + kSquare +
                                      "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>") +
                               "</bldg:Building></core:cityObjectMember>");
  CityGmlOptions small;
  small.dom_max_bytes = xml.size() - 1;
  std::vector<Problem> problems;
  SourceInfo info;
  std::size_t meshes = 0;
  read_citygml_buffer(xml, "inline.gml", small, [&](Mesh&&) { ++meshes; }, problems, info);
  EXPECT_EQ(meshes, 1u);
  EXPECT_EQ(info.bytes_streamed, xml.size());
  EXPECT_NE(info.streamed_why.find("larger than"), std::string::npos) << info.streamed_why;
}

TEST(XmlText, AcceptsUtf8AndPredefinedReferencesOnly) {
  using xml::check_xml_text;
  EXPECT_EQ(check_xml_text("plain <a b='1'>text</a>\n\t\r"), "");
  EXPECT_EQ(check_xml_text("&amp;&lt;&gt;&quot;&apos;&#65;&#x1F600;"), "");
  EXPECT_EQ(check_xml_text("K\xC3\xB6ln \xE6\x9D\xB1\xE4\xBA\xAC \xF0\x9F\x98\x80"), "");  // Köln, 東京, an emoji
  EXPECT_NE(check_xml_text("&nbsp;"), "");
  EXPECT_NE(check_xml_text("a & b"), "");
  EXPECT_NE(check_xml_text("&#xD800;"), "");   // a surrogate
  EXPECT_NE(check_xml_text("&#1114112;"), "");  // past U+10FFFF
  EXPECT_NE(check_xml_text("&#;"), "");
  EXPECT_NE(check_xml_text("12345678\x7F\x01"), "");
  EXPECT_NE(check_xml_text("\xED\xA0\x80"), "");  // a UTF-8 surrogate
  EXPECT_NE(check_xml_text("\xEF\xBF\xBE"), "");  // U+FFFE
  EXPECT_NE(check_xml_text("\xF4\x90\x80\x80"), "");  // past U+10FFFF
  EXPECT_NE(check_xml_text("abc\xE6\x9D"), "");  // cut short at the end
  EXPECT_NE(check_xml_text(std::string("abcdefgh\0", 9)), "");
}

}  // namespace
}  // namespace groundplan::gis
