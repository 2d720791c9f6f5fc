// SPDX-License-Identifier: MIT
// --close-gaps (issue 9): known answers on small cases (walls straight, corners sharp, untouched plans
// vertex for vertex), and random rows of rectangles against GEOS's closing (buffer(+d) then
// buffer(-d), mitre joins, the same mitre limit) of the union; validity and non-overlap through GEOS.
#include <gtest/gtest.h>

#include <geos_c.h>
#include <groundplan/error.h>
#include <groundplan/level_of_detail.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iomanip>
#include <memory>
#include <random>
#include <sstream>

#include "union_generators.h"
#include "union_test_util.h"

namespace groundplan {
namespace {

constexpr double kMitreLimit = 10.0;  // close_gaps.cpp's limit, as a multiple of d

UnionParams one_thread() {
  UnionParams p;
  p.threads = 1;
  p.device = Device::Cpu;
  return p;
}

// Plans as the pipeline makes them: the exact union of one footprint per polygon.
std::vector<GroundPlan> plans_of(const std::vector<Polygon>& polys, std::vector<Footprint>* fps_out = nullptr) {
  std::vector<Footprint> fps;
  for (const Polygon& p : polys) fps.push_back(Footprint{{p}, "f" + std::to_string(fps.size()), {}, {}, 0, 0});
  std::vector<Problem> problems;
  auto plans = build_ground_plans(fps, one_thread(), problems);
  EXPECT_TRUE(problems.empty());
  if (fps_out) *fps_out = fps;
  return plans;
}

std::vector<Footprint> as_footprints(const std::vector<GroundPlan>& plans) {
  std::vector<Footprint> fps;
  for (const GroundPlan& g : plans) fps.push_back(Footprint{{g.polygon}, {}, {}, {}, 0, 0});
  return fps;
}

// ---- GEOS reference: the closing of the union by d with mitre joins ----

struct Geos {
  GEOSContextHandle_t h = GEOS_init_r();
  ~Geos() { GEOS_finish_r(h); }
};

GEOSGeometry* ring_geom(GEOSContextHandle_t h, const Ring& r) {
  GEOSCoordSequence* s = GEOSCoordSeq_create_r(h, static_cast<unsigned>(r.size() + 1), 2);
  for (std::size_t i = 0; i <= r.size(); ++i) GEOSCoordSeq_setXY_r(h, s, static_cast<unsigned>(i), r[i % r.size()].x, r[i % r.size()].y);
  return GEOSGeom_createLinearRing_r(h, s);
}

GEOSGeometry* polygon_geom(GEOSContextHandle_t h, const Polygon& p) {
  std::vector<GEOSGeometry*> holes;
  for (const Ring& r : p.holes) holes.push_back(ring_geom(h, r));
  return GEOSGeom_createPolygon_r(h, ring_geom(h, p.outer), holes.data(), static_cast<unsigned>(holes.size()));
}

Ring ring_of(GEOSContextHandle_t h, const GEOSGeometry* ring) {
  const GEOSCoordSequence* s = GEOSGeom_getCoordSeq_r(h, ring);
  unsigned n = 0;
  GEOSCoordSeq_getSize_r(h, s, &n);
  Ring r;
  for (unsigned i = 0; i + 1 < n; ++i) {
    double x, y;
    GEOSCoordSeq_getXY_r(h, s, i, &x, &y);
    r.push_back({x, y});
  }
  return r;
}

std::vector<GroundPlan> plans_of_geom(GEOSContextHandle_t h, const GEOSGeometry* g) {
  std::vector<GroundPlan> out;
  const int n = GEOSGetNumGeometries_r(h, g);
  for (int i = 0; i < n; ++i) {
    const GEOSGeometry* p = GEOSGetGeometryN_r(h, g, i);
    if (GEOSGeomTypeId_r(h, p) != GEOS_POLYGON || GEOSisEmpty_r(h, p)) continue;
    GroundPlan gp;
    gp.polygon.outer = ring_of(h, GEOSGetExteriorRing_r(h, p));
    for (int k = 0; k < GEOSGetNumInteriorRings_r(h, p); ++k) gp.polygon.holes.push_back(ring_of(h, GEOSGetInteriorRingN_r(h, p, k)));
    out.push_back(std::move(gp));
  }
  return out;
}

std::vector<GroundPlan> geos_closing(const std::vector<GroundPlan>& plans, double d) {
  Geos g;
  std::vector<GEOSGeometry*> parts;
  for (const GroundPlan& p : plans) parts.push_back(polygon_geom(g.h, p.polygon));
  GEOSGeometry* all = GEOSGeom_createCollection_r(g.h, GEOS_MULTIPOLYGON, parts.data(), static_cast<unsigned>(parts.size()));
  GEOSGeometry* u = GEOSUnaryUnion_r(g.h, all);
  GEOSBufferParams* bp = GEOSBufferParams_create_r(g.h);
  GEOSBufferParams_setJoinStyle_r(g.h, bp, GEOSBUF_JOIN_MITRE);
  GEOSBufferParams_setMitreLimit_r(g.h, bp, kMitreLimit);
  GEOSGeometry* grown = GEOSBufferWithParams_r(g.h, u, bp, d);
  GEOSGeometry* closed = GEOSBufferWithParams_r(g.h, grown, bp, -d);
  auto out = plans_of_geom(g.h, closed);
  for (GEOSGeometry* x : {all, u, grown, closed}) GEOSGeom_destroy_r(g.h, x);
  GEOSBufferParams_destroy_r(g.h, bp);
  return out;
}

// Area of (input union) \ result, through GEOS: the closing must contain its input.
double area_lost(const std::vector<GroundPlan>& input, const std::vector<GroundPlan>& result) {
  Geos g;
  auto collect = [&](const std::vector<GroundPlan>& ps) {
    std::vector<GEOSGeometry*> parts;
    for (const GroundPlan& p : ps) parts.push_back(polygon_geom(g.h, p.polygon));
    return GEOSGeom_createCollection_r(g.h, GEOS_MULTIPOLYGON, parts.data(), static_cast<unsigned>(parts.size()));
  };
  GEOSGeometry* a = collect(input);
  GEOSGeometry* b = collect(result);
  GEOSGeometry* ua = GEOSUnaryUnion_r(g.h, a);
  GEOSGeometry* ub = GEOSUnaryUnion_r(g.h, b);
  GEOSGeometry* diff = GEOSDifference_r(g.h, ua, ub);
  double area = 0;
  GEOSArea_r(g.h, diff, &area);
  for (GEOSGeometry* x : {a, b, ua, ub, diff}) GEOSGeom_destroy_r(g.h, x);
  return area;
}

bool inside(const std::vector<GroundPlan>& plans, Point2 p) {
  auto crossings = [&](const Ring& r) {
    bool in = false;
    for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++)
      if ((r[i].y > p.y) != (r[j].y > p.y) && p.x < r[j].x + (p.y - r[j].y) * (r[i].x - r[j].x) / (r[i].y - r[j].y)) in = !in;
    return in;
  };
  for (const GroundPlan& g : plans) {
    bool in = crossings(g.polygon.outer);
    for (const Ring& h : g.polygon.holes) in = in != crossings(h);
    if (in) return true;
  }
  return false;
}

// Every check the closing promises, GEOS as the reference: returns the comparison.
gis::GeosComparison check_against_geos(const std::vector<GroundPlan>& input, const std::vector<GroundPlan>& out, double D,
                                       double rel_tol = 1e-6) {
  const auto ref = geos_closing(input, D / 2);
  const auto cmp = gis::compare_with_geos(as_footprints(input), out, &ref);
  EXPECT_TRUE(cmp.matches(rel_tol)) << cmp.summary();
  EXPECT_EQ(cmp.invalid_ours, 0u) << cmp.first_invalid_reason;
  EXPECT_EQ(cmp.overlapping_ours, 0u);
  double area_in = 0;
  for (const GroundPlan& g : input) area_in += g.area_m2;
  EXPECT_LE(area_lost(input, out), 1e-9 * area_in) << "the closing must contain its input";
  return cmp;
}

std::vector<Point2> sorted(Ring r) {
  std::sort(r.begin(), r.end(), [](const Point2& a, const Point2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  return r;
}

void expect_same_plans(const std::vector<GroundPlan>& a, const std::vector<GroundPlan>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].polygon.outer, b[i].polygon.outer) << "plan " << i;
    EXPECT_EQ(a[i].polygon.holes, b[i].polygon.holes) << "plan " << i;
    EXPECT_EQ(a[i].members, b[i].members) << "plan " << i;
  }
}

constexpr double X0 = 500000.0, Y0 = 5400000.0;  // UTM-like: coordinates with 1e-10 m ulps

// Each known answer is checked in two frames: axis-aligned at UTM coordinates (offsets exact enough
// that the closing's arithmetic often rounds back onto the input), and rotated by 0.3 rad (every
// coordinate inexact, walls collinear only up to rounding: what reconciliation is for).
struct Frame {
  double angle;
  Point2 operator()(double x, double y) const {
    if (angle == 0) return {X0 + x, Y0 + y};
    return {X0 + std::cos(angle) * x - std::sin(angle) * y, Y0 + std::sin(angle) * x + std::cos(angle) * y};
  }
  Polygon operator()(std::initializer_list<Point2> local) const {
    Polygon p;
    for (const Point2& q : local) p.outer.push_back((*this)(q.x, q.y));
    return p;
  }
  Ring ring(std::initializer_list<Point2> local) const { return (*this)(local).outer; }
  Polygon rect(double x0, double y0, double x1, double y1) const { return (*this)({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}); }
};
constexpr Frame kFrames[] = {{0.0}, {0.3}};

bool has_vertex(const GroundPlan& g, const Point2& p) {
  if (std::find(g.polygon.outer.begin(), g.polygon.outer.end(), p) != g.polygon.outer.end()) return true;
  for (const Ring& h : g.polygon.holes)
    if (std::find(h.begin(), h.end(), p) != h.end()) return true;
  return false;
}

// Walls straight and corners sharp: every vertex of the result is a vertex of the input, the given
// corners are there and the given (filled) ones are not.
void expect_input_vertices(const GroundPlan& g, const std::vector<GroundPlan>& in, const std::vector<Point2>& corners,
                           const std::vector<Point2>& gone) {
  std::vector<Point2> all;
  for (const GroundPlan& p : in) {
    all.insert(all.end(), p.polygon.outer.begin(), p.polygon.outer.end());
    for (const Ring& h : p.polygon.holes) all.insert(all.end(), h.begin(), h.end());
  }
  auto check = [&](const Ring& r) {
    for (const Point2& v : r)
      EXPECT_NE(std::find(all.begin(), all.end(), v), all.end())
          << "new vertex " << std::setprecision(17) << v.x << " " << v.y;
  };
  check(g.polygon.outer);
  for (const Ring& h : g.polygon.holes) check(h);
  for (const Point2& c : corners) EXPECT_TRUE(has_vertex(g, c)) << "corner lost " << std::setprecision(17) << c.x << " " << c.y;
  for (const Point2& c : gone) EXPECT_FALSE(has_vertex(g, c)) << "filled corner kept " << std::setprecision(17) << c.x << " " << c.y;
}

// ---- known answers ----

TEST(LodCloseGaps, RejectsBadWidthAndKeepsEmptyInput) {
  EXPECT_THROW(close_gaps({}, 0.0, one_thread()), InvalidArgument);
  EXPECT_THROW(close_gaps({}, -0.1, one_thread()), InvalidArgument);
  EXPECT_THROW(close_gaps({}, std::nan(""), one_thread()), InvalidArgument);
  EXPECT_THROW(close_gaps({}, INFINITY, one_thread()), InvalidArgument);
  EXPECT_TRUE(close_gaps({}, 0.1, one_thread()).empty());
}

TEST(LodCloseGaps, TwoRectangles5cmApartBecomeOneRectangle) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    const auto in = plans_of({f.rect(0, 0, 10, 5), f.rect(10.05, 0, 20, 5)});
    ASSERT_EQ(in.size(), 2u);
    LodStats st;
    const auto out = close_gaps(in, 0.1, one_thread(), &st);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_TRUE(out[0].polygon.holes.empty());
    if (f.angle == 0) {  // exactly the four outer corners of the input
      EXPECT_EQ(sorted(out[0].polygon.outer), sorted({f(0, 0), f(20, 0), f(20, 5), f(0, 5)}));
    } else {  // the gap's corners are collinear with the walls only up to rounding: they may stay
      expect_input_vertices(out[0], in, {f(0, 0), f(20, 0), f(20, 5), f(0, 5)}, {});
    }
    EXPECT_EQ(out[0].members, (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(st.close_plans_before, 2u);
    EXPECT_EQ(st.close_plans_after, 1u);
    EXPECT_NEAR(st.close_area_added_m2, (10.05 - 10) * 5, 1e-6);
    check_against_geos(in, out, 0.1);
  }
}

TEST(LodCloseGaps, Rectangles15cmApartStayAsTheyWere) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    const auto in = plans_of({f.rect(0, 0, 10, 5), f.rect(10.15, 0, 20, 5)});
    LodStats st;
    const auto out = close_gaps(in, 0.1, one_thread(), &st);
    expect_same_plans(out, in);
    EXPECT_EQ(st.close_area_added_m2, 0.0);
    check_against_geos(in, out, 0.1);
  }
}

TEST(LodCloseGaps, USlotAndNarrowNotchFillWideNotchStays) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    // a 10 m square with an 8 cm slot 7 m deep from the top, an 8 cm wide 6 cm deep notch in the
    // bottom wall and a 1 m wide 6 cm deep notch in the left wall
    const auto in = plans_of({f({{0, 0}, {3, 0}, {3, 0.06}, {3.08, 0.06}, {3.08, 0}, {10, 0}, {10, 10}, {5.08, 10}, {5.08, 3},
                                 {5, 3}, {5, 10}, {0, 10}, {0, 6}, {0.06, 6}, {0.06, 5}, {0, 5}})});
    const auto out = close_gaps(in, 0.1, one_thread());
    ASSERT_EQ(out.size(), 1u);
    const std::vector<Point2> corners{f(0, 0), f(10, 0), f(10, 10), f(0, 10), f(0, 6), f(0.06, 6), f(0.06, 5), f(0, 5)};
    if (f.angle == 0) {
      EXPECT_EQ(sorted(out[0].polygon.outer), sorted(corners));
    }
    expect_input_vertices(out[0], in, corners, {f(3, 0.06), f(3.08, 0.06), f(5, 3), f(5.08, 3)});
    check_against_geos(in, out, 0.1);
  }
}

TEST(LodCloseGaps, LShapeAndReflexCornerStayVertexIdentical) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    const auto in = plans_of({f({{0, 0}, {12.3, 0}, {12.3, 4.1}, {4.7, 4.1}, {4.7, 9.9}, {0, 9.9}}),
                              f.rect(6, 5, 9, 8)});  // a neighbour 0.9 m away in the corner
    ASSERT_EQ(in.size(), 2u);
    const auto out = close_gaps(in, 0.1, one_thread());
    expect_same_plans(out, in);
    check_against_geos(in, out, 0.1);
  }
}

TEST(LodCloseGaps, NarrowCourtyardFilledWideOneKept) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    Polygon p = f.rect(0, 0, 20, 20);
    p.holes.push_back(f.ring({{5, 10}, {5, 10.05}, {15, 10.05}, {15, 10}}));  // 5 cm
    p.holes.push_back(f.ring({{5, 5}, {5, 6}, {6, 6}, {6, 5}}));              // 1 m
    const auto in = plans_of({p});
    ASSERT_EQ(in.size(), 1u);
    ASSERT_EQ(in[0].polygon.holes.size(), 2u);
    const auto out = close_gaps(in, 0.1, one_thread());
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].polygon.outer, in[0].polygon.outer);
    ASSERT_EQ(out[0].polygon.holes.size(), 1u);
    EXPECT_EQ(sorted(out[0].polygon.holes[0]), sorted(f.ring({{5, 5}, {5, 6}, {6, 6}, {6, 5}})));
    check_against_geos(in, out, 0.1);
  }
}

TEST(LodCloseGaps, WedgeGapClosesOnlyWhereNarrowerThanD) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    // the gap widens from 2 cm at y = 0 to 30 cm at y = 10: narrower than 10 cm below y ~ 2.86
    const auto in = plans_of({f.rect(0, 0, 10, 10), f({{10.02, 0}, {20, 0}, {20, 10}, {10.3, 10}})});
    ASSERT_EQ(in.size(), 2u);
    const auto out = close_gaps(in, 0.1, one_thread());
    ASSERT_EQ(out.size(), 1u);
    EXPECT_TRUE(inside(out, f(10.01, 0.5)));
    EXPECT_TRUE(inside(out, f(10.02, 2.0)));   // gap 7.6 cm
    EXPECT_FALSE(inside(out, f(10.05, 4.0)));  // gap 13.2 cm
    EXPECT_FALSE(inside(out, f(10.1, 9.0)));
    // the input's corners are still corners of the result, the gap's bottom ones are gone
    for (const Point2& c : {f(0, 0), f(20, 0), f(20, 10), f(10.3, 10), f(10, 10), f(0, 10)})
      EXPECT_TRUE(has_vertex(out[0], c)) << c.x - X0 << " " << c.y - Y0;
    if (f.angle == 0) {  // rotated, they are collinear with the bottom wall only up to rounding and may stay
      EXPECT_FALSE(has_vertex(out[0], f(10, 0)));
      EXPECT_FALSE(has_vertex(out[0], f(10.02, 0)));
    }
    check_against_geos(in, out, 0.1);
  }
}

TEST(LodCloseGaps, SharpSpikeKeepsItsTip) {
  for (const Frame& f : kFrames) {
    SCOPED_TRACE(f.angle);
    // a 4-degree spike: its mitre (1.43 m unclipped) is clipped at the limit (0.5 m), and the closing
    // gives the spike back whole; a wall 30 cm beyond its tip is within reach of the clipped mitre
    const double tip = 20 * std::tan(2.0 * M_PI / 180);
    const auto in = plans_of({f({{0, 0}, {20, tip}, {0, 2 * tip}}), f.rect(-5, -1, -0.05, 3), f.rect(20.3, tip - 2, 25, tip + 2)});
    ASSERT_EQ(in.size(), 3u);
    const auto out = close_gaps(in, 0.1, one_thread());
    EXPECT_EQ(out.size(), 2u);  // the dilations join, the erosion cuts the bridge again
    EXPECT_TRUE(std::any_of(out.begin(), out.end(), [&](const GroundPlan& g) { return has_vertex(g, f(20, tip)); }));
    check_against_geos(in, out, 0.1);
  }
}

// ---- random rows of rectangles, axis-aligned and rotated, gaps in [0, 2D] ----

std::vector<Polygon> random_row(std::mt19937_64& rng, double D) {
  std::uniform_real_distribution<double> size(2, 12), gap(0, 2 * D), shift(-3, 3), unit(0, 1);
  const double angle = unit(rng) < 0.4 ? 0.0 : unit(rng) * M_PI;
  const double c = std::cos(angle), s = std::sin(angle);
  const Point2 o{X0 + 1000 * unit(rng), Y0 + 1000 * unit(rng)};
  auto place = [&](double x, double y) { return Point2{o.x + c * x - s * y, o.y + s * x + c * y}; };
  std::vector<Polygon> out;
  double x = 0;
  const int n = 2 + static_cast<int>(unit(rng) * 5);
  for (int i = 0; i < n; ++i) {
    const double w = size(rng), h = size(rng), y = shift(rng);
    out.push_back(Polygon{{place(x, y), place(x + w, y), place(x + w, y + h), place(x, y + h)}, {}});
    if (unit(rng) < 0.3) {  // a second row above, a random gap away
      const double y2 = y + h + gap(rng);
      out.push_back(Polygon{{place(x, y2), place(x + w, y2), place(x + w, y2 + 4), place(x, y2 + 4)}, {}});
    }
    x += w + gap(rng);
  }
  return out;
}

TEST(LodCloseGaps, RandomRowsMatchGeos) {
  std::mt19937_64 rng(20240609);
  double worst = 0;
  int merged = 0;
  for (int it = 0; it < 150; ++it) {
    const double D = it % 3 == 0 ? 0.1 : 0.3;
    const auto polys = random_row(rng, D);
    const auto in = plans_of(polys);
    LodStats st;
    const auto out = close_gaps(in, D, one_thread(), &st);
    const auto cmp = check_against_geos(in, out, D);
    worst = std::max(worst, cmp.symdiff_area / std::max(cmp.area_geos, 1e-300));
    merged += out.size() < in.size();
    // members: every input building once
    std::vector<std::uint32_t> all;
    for (const GroundPlan& g : out) all.insert(all.end(), g.members.begin(), g.members.end());
    std::sort(all.begin(), all.end());
    EXPECT_EQ(all.size(), polys.size());
    EXPECT_TRUE(std::adjacent_find(all.begin(), all.end()) == all.end());
    if (::testing::Test::HasFailure()) {
      std::ostringstream m;
      m.precision(17);
      for (const Polygon& p : polys) m << gis::to_wkt(p) << "\n";
      ADD_FAILURE() << "case " << it << " D " << D << "\n" << m.str();
      break;
    }
  }
  EXPECT_GT(merged, 50);  // the cases do exercise closing
  std::cout << "worst relative symmetric difference with GEOS: " << worst << "\n";
}

TEST(LodCloseGaps, SyntheticCityBlocksAgreeWithGeos) {
  const auto fps = testing::synthetic_city(2000, 7);
  std::vector<Problem> problems;
  const auto in = build_ground_plans(fps, one_thread(), problems);
  LodStats st;
  const auto out = close_gaps(in, 0.1, UnionParams{}, &st);
  const auto cmp = check_against_geos(in, out, 0.1);
  EXPECT_EQ(st.close_plans_before, in.size());
  EXPECT_EQ(st.close_plans_after, out.size());
  std::cout << "city: " << in.size() << " -> " << out.size() << " plans, +" << st.close_area_added_m2 << " m2; "
            << cmp.summary() << "\n";
}

}  // namespace
}  // namespace groundplan
