// SPDX-License-Identifier: MIT
// Working frames reuse a finished frame's PROJ objects (issue 14: a folder of PLATEAU tiles made them
// once a file, ~100M instructions each). A reused frame must answer exactly as a fresh one: its own
// UTM zone, its own notes, its own file in messages, whatever the frame before it decided.
#include <groundplan/error.h>
#include <groundplan/gis/crs.h>

#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

namespace groundplan::gis {
namespace {

// ETRS89 geographic, latitude first: a key no other test uses, so the first frame here is made afresh.
constexpr const char* kSource = "urn:ogc:def:crs:EPSG::4258";
// The same CRS in another spelling: another key, so frames of it never reuse kSource's objects.
constexpr const char* kSameCrsOtherKey = "http://www.opengis.net/def/crs/EPSG/0/4258";

struct Answer {
  int epsg = 0;
  double x = 0, y = 0;
  std::vector<std::string> notes;
};

/// A frame decided at (lat, lon), then one point transformed.
Answer run(const char* srs, double lat, double lon, double px_lat, double py_lon) {
  WorkingFrame f(srs);
  f.decide(lat, lon);
  Answer a;
  a.epsg = f.working_crs().epsg;
  a.x = px_lat;
  a.y = py_lon;
  EXPECT_TRUE(f.transform_point(a.x, a.y));
  a.notes = f.notes();
  return a;
}

TEST(WorkingFrameReuse, ReusedFrameAnswersAsAFreshOne) {
  const std::size_t before = working_frame_setups();
  // Hamburg (UTM 32N), then Berlin (33N), then Hamburg again: the third frame reuses an Impl that last
  // decided 33N.
  const Answer a = run(kSource, 53.55, 9.99, 53.5501, 9.9902);
  const Answer b = run(kSource, 52.52, 13.40, 52.5203, 13.4051);
  const Answer c = run(kSource, 53.55, 9.99, 53.5501, 9.9902);
  EXPECT_EQ(working_frame_setups(), before + 1) << "frames of one key should make their PROJ objects once";
  EXPECT_EQ(a.epsg, 32632);
  EXPECT_EQ(b.epsg, 32633);
  EXPECT_EQ(c.epsg, 32632);
  EXPECT_EQ(c.x, a.x);
  EXPECT_EQ(c.y, a.y);
  EXPECT_EQ(c.notes, a.notes) << "a reused frame must not carry the notes of the frame before it";
  ASSERT_EQ(b.notes.size(), 1u);
  EXPECT_NE(b.notes[0].find("EPSG:32633"), std::string::npos) << b.notes[0];

  // Bit for bit what a frame made afresh gives (another key for the same CRS: its own PROJ objects).
  const std::size_t fresh_before = working_frame_setups();
  const Answer fresh = run(kSameCrsOtherKey, 53.55, 9.99, 53.5501, 9.9902);
  EXPECT_EQ(working_frame_setups(), fresh_before + 1);
  EXPECT_EQ(fresh.epsg, a.epsg);
  EXPECT_EQ(fresh.x, a.x);
  EXPECT_EQ(fresh.y, a.y);
  EXPECT_GT(a.x, 560000);  // Hamburg's easting in 32N
  EXPECT_LT(a.x, 570000);
}

TEST(WorkingFrameReuse, UndecidedFrameAfterADecidedOne) {
  { run(kSource, 48.14, 11.58, 48.14, 11.58); }  // leaves a decided Impl in the pool
  WorkingFrame f(kSource, {}, "second.gml");
  EXPECT_FALSE(f.decided()) << "a reused frame must start undecided, as a fresh one does";
  EXPECT_FALSE(f.working_crs().known);
  // Its messages name its own file, not the one of the frame before.
  try {
    f.decide(5.5e6, 6.8e5);  // metres under a geographic label
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("second.gml: "), std::string::npos) << e.what();
  }
}

TEST(WorkingFrameReuse, TargetFramesAndMovesGiveBackOnce) {
  CrsOptions to_utm;
  to_utm.target_srs = "EPSG:25832";
  const std::size_t before = working_frame_setups();
  WorkingFrame a(kSource, to_utm, "a.gml");
  WorkingFrame b(std::move(a));  // moved-from a gives nothing back
  double x = 53.5501, y = 9.9902;
  ASSERT_TRUE(b.transform_point(x, y));
  WorkingFrame c(kSource, to_utm, "c.gml");  // b still lives: c is made afresh
  c = std::move(b);                          // c's own Impl goes back to the pool here
  double x2 = 53.5501, y2 = 9.9902;
  ASSERT_TRUE(c.transform_point(x2, y2));
  EXPECT_EQ(x2, x);
  EXPECT_EQ(y2, y);
  EXPECT_EQ(working_frame_setups(), before + 2);
  WorkingFrame d(kSource, to_utm, "d.gml");  // takes the Impl c gave back
  EXPECT_EQ(working_frame_setups(), before + 2);
  EXPECT_EQ(d.working_crs().epsg, 25832);
}

TEST(WorkingFrameReuse, ManyThreadsEachWithTheirOwnFrames) {
  const Answer hamburg = run(kSource, 53.55, 9.99, 53.5501, 9.9902);
  const Answer berlin = run(kSource, 52.52, 13.40, 52.5203, 13.4051);
  constexpr int kThreads = 8, kFrames = 40;
  std::vector<int> wrong(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < kFrames; ++i) {
        const bool h = (i + t) % 2 == 0;
        const Answer r = h ? run(kSource, 53.55, 9.99, 53.5501, 9.9902) : run(kSource, 52.52, 13.40, 52.5203, 13.4051);
        const Answer& want = h ? hamburg : berlin;
        if (r.epsg != want.epsg || r.x != want.x || r.y != want.y || r.notes != want.notes) ++wrong[t];
      }
    });
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(wrong[t], 0) << "thread " << t;
}

}  // namespace
}  // namespace groundplan::gis
