// SPDX-License-Identifier: MIT
// A search tool, not a test: random near-degenerate triangle sets at projected-CRS magnitudes, each united
// by this engine and by GEOS UnaryUnion and compared by compare_with_geos, whose adjudication decides every
// difference exactly against the input. Prints, as WKT, the inputs where GEOS's floating-point overlay keeps a
// hole the input covers ("invented") or closes a hole the input has ("dropped"), and any input where our plans
// are found wrong. tests/unit/core/verify_adjudication_test.cpp pins inputs found this way.
//
//   geos_disagreement_search [--trials 200000] [--seed 1] [--max-found 5] [--wide] [--min-size 1e-6]
// (--wide: only inputs where the plans and GEOS differ by more than the snap pitch somewhere, where a check
// without adjudication says MISMATCH)
#include <groundplan/gis/geos_reference.h>
#include <groundplan/ground_plans.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace groundplan;

/// Triangles around a small cluster far from the origin: corners are a few shared base points, points on
/// (or a few ulps off) the segments between them, and points a few ulps to micrometres from each other, so
/// that edges cross at points that are not doubles and nearly meet where they should meet exactly.
std::vector<Footprint> make_case(std::mt19937_64& rng, double min_exp) {
  std::uniform_real_distribution<double> u(0, 1);
  const double ox = 3e5 + std::floor(u(rng) * 1e5), oy = 5.4e6 + std::floor(u(rng) * 1e5);
  const double scale = std::pow(10.0, min_exp + (1 - min_exp) * u(rng));  // 10^min_exp .. 10 m
  std::vector<Point2> pts;
  const int base = 3 + static_cast<int>(rng() % 4);
  for (int i = 0; i < base; ++i) pts.push_back({ox + scale * u(rng), oy + scale * u(rng)});
  const int extra = 2 + static_cast<int>(rng() % 5);
  for (int i = 0; i < extra; ++i) {
    const Point2 a = pts[rng() % pts.size()], b = pts[rng() % pts.size()];
    const double t = u(rng);
    Point2 p{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};  // on a->b up to rounding
    const int ulps = static_cast<int>(rng() % 5) - 2;
    for (int k = 0; k < std::abs(ulps); ++k) p.x = std::nextafter(p.x, ulps > 0 ? INFINITY : -INFINITY);
    pts.push_back(p);
  }
  std::vector<Footprint> fps;
  const int tris = 2 + static_cast<int>(rng() % 5);
  for (int i = 0; i < tris; ++i) {
    Footprint f;
    f.source_id = "t" + std::to_string(i);
    f.polygons.push_back(Polygon{{pts[rng() % pts.size()], pts[rng() % pts.size()], pts[rng() % pts.size()]}, {}});
    fps.push_back(std::move(f));
  }
  return fps;
}

void print_case(const char* what, const std::vector<Footprint>& fps, const std::vector<GroundPlan>& plans,
                const gis::GeosComparison& c) {
  std::printf("%s: %s\n  %s\n", what, c.verdict_line().c_str(), c.summary().c_str());
  for (const Footprint& f : fps) std::printf("  %s\n", gis::to_wkt(f.polygons[0]).c_str());
  for (const GroundPlan& p : plans) std::printf("  plan %s\n", gis::to_wkt(p.polygon).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  long trials = 200000, max_found = 5;
  double min_exp = -6;     // --min-size 1e-6: the smallest cluster, metres
  bool wide_only = false;  // --wide: only cases whose differences are not all narrower than the snap pitch
  unsigned long seed = 1;
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--wide")) wide_only = true;
    else if (has_value && !std::strcmp(argv[i], "--trials")) trials = std::atol(argv[++i]);
    else if (has_value && !std::strcmp(argv[i], "--seed")) seed = std::strtoul(argv[++i], nullptr, 10);
    else if (has_value && !std::strcmp(argv[i], "--max-found")) max_found = std::atol(argv[++i]);
    else if (has_value && !std::strcmp(argv[i], "--min-size")) min_exp = std::log10(std::atof(argv[++i]));
    else {
      std::fprintf(stderr, "unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  std::mt19937_64 rng(seed);
  long invented = 0, dropped = 0, geos_wrong = 0, ours_wrong = 0;
  for (long t = 0; t < trials; ++t) {
    const std::vector<Footprint> fps = make_case(rng, min_exp);
    std::vector<Problem> problems;
    UnionParams params;
    params.threads = 1;
    const std::vector<GroundPlan> plans = build_ground_plans(fps, params, problems);
    const gis::GeosComparison c = gis::compare_with_geos(fps, plans);
    if (wide_only && !(c.differences_checked && !c.differences_below_pitch)) continue;
    if (c.holes_geos_artifacts && invented++ < max_found) print_case("GEOS invented a hole", fps, plans, c);
    if (c.holes_geos_dropped && dropped++ < max_found) print_case("GEOS dropped a hole", fps, plans, c);
    if (c.places_geos_wrong && !c.holes_geos_artifacts && !c.holes_geos_dropped && geos_wrong++ < max_found)
      print_case("GEOS wrong elsewhere", fps, plans, c);
    if ((c.places_ours_wrong || c.places_undecided || !c.matches()) && ours_wrong++ < max_found)
      print_case("OURS WRONG (or undecided)", fps, plans, c);
  }
  std::printf("%ld trials: GEOS invented a hole in %ld, dropped one in %ld, wrong elsewhere in %ld; ours wrong in %ld\n",
              trials, invented, dropped, geos_wrong, ours_wrong);
  return 0;
}
