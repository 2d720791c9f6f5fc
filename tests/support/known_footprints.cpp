// SPDX-License-Identifier: MIT
#include "known_footprints.h"

#include <groundplan/types.h>

#include <algorithm>
#include <array>
#include <functional>
#include <random>

namespace groundplan::test {
namespace {

using Ring3 = std::vector<Point3>;

struct Face {
  Ring3 ring;           // convex, no three corners in a line, counter-clockwise seen from outside
  bool ground = false;  // lies on the ground: written only in the "floor" variant
};

struct Model {
  std::vector<Face> faces;
  std::string true_wkt;
  double true_area_m2 = 0;
  double shadow_area_m2 = 0;
};

/// Wall from plan corner p to q (outline counter-clockwise, so the outside is on the right), z0..z1.
Face wall(double px, double py, double qx, double qy, double z0, double z1) {
  return {{{px, py, z0}, {qx, qy, z0}, {qx, qy, z1}, {px, py, z1}}};
}

/// Horizontal rectangle at z, facing up (`up`) or down.
Face flat(double x0, double y0, double x1, double y1, double z, bool up, bool ground = false) {
  Ring3 r{{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  if (!up) std::reverse(r.begin(), r.end());
  return {r, ground};
}

/// The four walls of the rectangle [x0,x1] x [y0,y1], z0..z1.
void walls(Model& m, double x0, double y0, double x1, double y1, double z0, double z1) {
  m.faces.push_back(wall(x0, y0, x1, y0, z0, z1));
  m.faces.push_back(wall(x1, y0, x1, y1, z0, z1));
  m.faces.push_back(wall(x1, y1, x0, y1, z0, z1));
  m.faces.push_back(wall(x0, y1, x0, y0, z0, z1));
}

/// A closed box; its bottom is a ground face when it stands on the ground (z0 == 0).
void box(Model& m, double x0, double y0, double z0, double x1, double y1, double z1) {
  walls(m, x0, y0, x1, y1, z0, z1);
  m.faces.push_back(flat(x0, y0, x1, y1, z1, true));
  m.faces.push_back(flat(x0, y0, x1, y1, z0, false, z0 == 0));
}

const char* kHouse = "POLYGON((0 0,10 0,10 8,0 8,0 0))";

/// Gable roof over a 10 x 8 house, 0.8 m eaves, no soffit: the roof planes are single sheets and
/// the walls end inside them (top edges on no roof edge), open underneath.
Model eaves_open() {
  Model m{{}, kHouse, 80, 11.6 * 9.6};
  m.faces.push_back(wall(0, 0, 10, 0, 0, 3));
  m.faces.push_back(wall(10, 8, 0, 8, 0, 3));
  m.faces.push_back({{{10, 0, 0}, {10, 8, 0}, {10, 8, 3}, {10, 4, 5}, {10, 0, 3}}});  // gables
  m.faces.push_back({{{0, 8, 0}, {0, 0, 0}, {0, 0, 3}, {0, 4, 5}, {0, 8, 3}}});
  m.faces.push_back({{{-0.8, -0.8, 2.6}, {10.8, -0.8, 2.6}, {10.8, 4, 5}, {-0.8, 4, 5}}});  // z = 3 + y/2
  m.faces.push_back({{{-0.8, 4, 5}, {10.8, 4, 5}, {10.8, 8.8, 2.6}, {-0.8, 8.8, 2.6}}});
  m.faces.push_back(flat(0, 0, 10, 8, 0, false, true));
  return m;
}

/// The same house with boxed eaves: a soffit at z 3 from the walls' tops out to the eaves all round,
/// gable ends closing the roof at x -0.8 and 10.8. Watertight but for the bottom.
Model eaves_soffit() {
  Model m{{}, kHouse, 80, 11.6 * 9.6};
  walls(m, 0, 0, 10, 8, 0, 3);
  const double a = -0.8, b = 10.8, c = 8.8;
  auto down = [&](Ring3 r) {  // listed counter-clockwise from above; the soffit faces down
    std::reverse(r.begin(), r.end());
    m.faces.push_back({r});
  };
  down({{a, a, 3}, {b, a, 3}, {10, 0, 3}, {0, 0, 3}});
  down({{b, a, 3}, {b, c, 3}, {10, 8, 3}, {10, 0, 3}});
  down({{b, c, 3}, {a, c, 3}, {0, 8, 3}, {10, 8, 3}});
  down({{a, c, 3}, {a, a, 3}, {0, 0, 3}, {0, 8, 3}});
  m.faces.push_back({{{a, a, 3}, {b, a, 3}, {b, 4, 5}, {a, 4, 5}}});
  m.faces.push_back({{{a, 4, 5}, {b, 4, 5}, {b, c, 3}, {a, c, 3}}});
  m.faces.push_back({{{a, c, 3}, {a, a, 3}, {a, 4, 5}}});
  m.faces.push_back({{{b, a, 3}, {b, c, 3}, {b, 4, 5}}});
  m.faces.push_back(flat(0, 0, 10, 8, 0, false, true));
  return m;
}

/// Walls of a 10 x 8 house (z 0..3) with a closed roof slab laid on them, 1 m eaves all round: the
/// walls' top edges lie in the slab's underside, not on its edges (issue 21: 200 m² instead of 80).
Model slab_roof() {
  Model m{{}, kHouse, 80, 12 * 10};
  walls(m, 0, 0, 10, 8, 0, 3);
  box(m, -1, -1, 3, 11, 9, 3.3);
  m.faces.push_back(flat(0, 0, 10, 8, 0, false, true));
  return m;
}

/// Ground floor 10 x 8 (z 0..3), upper storey 12 x 8 (z 3..6) cantilevered 2 m over x 10..12, one
/// solid: a soffit under the cantilever, the roof one face (T-junctions at x 10 on its edges).
Model cantilever() {
  Model m{{}, kHouse, 80, 12 * 8};
  walls(m, 0, 0, 10, 8, 0, 3);
  m.faces.push_back(wall(0, 0, 10, 0, 3, 6));
  m.faces.push_back(wall(10, 0, 12, 0, 3, 6));
  m.faces.push_back(wall(12, 0, 12, 8, 3, 6));
  m.faces.push_back(wall(12, 8, 10, 8, 3, 6));
  m.faces.push_back(wall(10, 8, 0, 8, 3, 6));
  m.faces.push_back(wall(0, 8, 0, 0, 3, 6));
  m.faces.push_back(flat(10, 0, 12, 8, 3, false));  // soffit
  m.faces.push_back(flat(0, 0, 12, 8, 6, true));
  m.faces.push_back(flat(0, 0, 10, 8, 0, false, true));
  return m;
}

/// A closed 10 x 8 house (z 0..6) with a balcony slab (3 x 1.5 m, z 3..3.2, a closed box) whose
/// back lies in the house's south wall.
Model balcony() {
  Model m{{}, kHouse, 80, 80 + 4.5};
  box(m, 0, 0, 0, 10, 8, 6);
  box(m, 3, -1.5, 3, 6, 0, 3.2);
  return m;
}

/// A 20 x 8 house on a slope: the east half stands 2 m higher (z 2), the roof at z 8. With the floor:
/// the two floor levels and the riser between them.
Model stepped_ground() {
  Model m{{}, "POLYGON((0 0,20 0,20 8,0 8,0 0))", 160, 160};
  m.faces.push_back(wall(0, 0, 10, 0, 0, 8));
  m.faces.push_back(wall(10, 0, 20, 0, 2, 8));
  m.faces.push_back(wall(20, 0, 20, 8, 2, 8));
  m.faces.push_back(wall(20, 8, 10, 8, 2, 8));
  m.faces.push_back(wall(10, 8, 0, 8, 0, 8));
  m.faces.push_back(wall(0, 8, 0, 0, 0, 8));
  m.faces.push_back(flat(0, 0, 20, 8, 8, true));
  m.faces.push_back(flat(0, 0, 10, 8, 0, false, true));
  m.faces.push_back(flat(10, 0, 20, 8, 2, false, true));
  m.faces.push_back({{{10, 0, 0}, {10, 8, 0}, {10, 8, 2}, {10, 0, 2}}, true});  // riser, facing +x
  return m;
}

/// A closed box (10 x 8, z 0..3) with a smaller closed box (6 x 4, z 3..6) set on its roof: the upper
/// box's bottom lies inside the lower box's top, no edge shared (SketchUp components).
Model stacked_boxes() {
  Model m{{}, kHouse, 80, 80};
  box(m, 0, 0, 0, 10, 8, 3);
  box(m, 2, 2, 3, 8, 6, 6);
  return m;
}

/// As stacked_boxes, the upper box (9 x 8) reaching 3 m beyond the lower one's east side.
Model stacked_overhang() {
  Model m{{}, kHouse, 80, 13 * 8};
  box(m, 0, 0, 0, 10, 8, 3);
  box(m, 4, 0, 3, 13, 8, 6);
  return m;
}

/// As stacked_boxes, the upper box (6 x 6) set on the lower one's north-east corner and reaching 3 m
/// beyond it both ways: no wall top of the lower box lies under its middle, only its own bottom edges
/// lie partly on the lower box's roof.
Model stacked_corner() {
  Model m{{}, kHouse, 80, 80 + 36 - 9};
  box(m, 0, 0, 0, 10, 8, 3);
  box(m, 7, 5, 3, 13, 11, 6);
  return m;
}

/// Two houses 5 m apart in one model.
Model disconnected() {
  Model m{{}, "MULTIPOLYGON(((0 0,10 0,10 8,0 8,0 0)),((15 0,21 0,21 5,15 5,15 0)))", 110, 110};
  box(m, 0, 0, 0, 10, 8, 3);
  box(m, 15, 0, 0, 21, 5, 5);
  return m;
}

/// A building of one closed mesh on a plan grid (lines xs, ys): cell (i, j) is solid from bottom[j][i] to
/// top[j][i] (top 0: empty). Stacked parts (plinth, podium, terraces, towers on a base) and arcades (cells
/// raised on pillars) as exporters write them without semantics: one solid, each side of a cell a wall
/// between its own and its neighbour's extent, every face's corners including each height where another
/// face meets its vertical edges (no T-junctions), bottoms at z 0 on the ground.
struct Cells {
  std::vector<double> xs, ys;
  std::vector<std::vector<std::array<double, 2>>> z;  // [j][i] = {bottom, top}
};

Model cells_model(const Cells& c, std::string true_wkt, double true_area, double shadow_area) {
  Model m{{}, std::move(true_wkt), true_area, shadow_area};
  const int nx = static_cast<int>(c.xs.size()) - 1, ny = static_cast<int>(c.ys.size()) - 1;
  auto cell = [&](int i, int j) -> std::array<double, 2> {
    if (i < 0 || j < 0 || i >= nx || j >= ny || c.z[j][i][1] <= 0) return {0, 0};
    return c.z[j][i];
  };
  // Heights met at grid corner (i, j): the bottoms and tops of the four cells around it.
  auto corner_heights = [&](int i, int j) {
    std::vector<double> h;
    for (int di : {-1, 0})
      for (int dj : {-1, 0}) {
        const auto e = cell(i + di, j + dj);
        if (e[1] > 0) h.insert(h.end(), {e[0], e[1]});
      }
    std::sort(h.begin(), h.end());
    h.erase(std::unique(h.begin(), h.end()), h.end());
    return h;
  };
  // Wall along the cell side from corner p to corner q (counter-clockwise round the cell: outside on the
  // right), z0..z1, with the corner heights strictly between on its vertical edges.
  auto side_wall = [&](int pi, int pj, int qi, int qj, double z0, double z1) {
    const Point2 p{c.xs[pi], c.ys[pj]}, q{c.xs[qi], c.ys[qj]};
    Ring3 r{{p.x, p.y, z0}, {q.x, q.y, z0}};
    for (double h : corner_heights(qi, qj))
      if (h > z0 && h < z1) r.push_back({q.x, q.y, h});
    r.push_back({q.x, q.y, z1});
    r.push_back({p.x, p.y, z1});
    std::vector<double> hp = corner_heights(pi, pj);
    for (auto it = hp.rbegin(); it != hp.rend(); ++it)
      if (*it > z0 && *it < z1) r.push_back({p.x, p.y, *it});
    m.faces.push_back({r});
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto e = cell(i, j);
      if (e[1] <= 0) continue;
      m.faces.push_back(flat(c.xs[i], c.ys[j], c.xs[i + 1], c.ys[j + 1], e[1], true));
      m.faces.push_back(flat(c.xs[i], c.ys[j], c.xs[i + 1], c.ys[j + 1], e[0], false, e[0] == 0));
      // Sides counter-clockwise: south, east, north, west; the neighbour across each.
      const int sides[4][6] = {{i, j, i + 1, j, i, j - 1},
                               {i + 1, j, i + 1, j + 1, i + 1, j},
                               {i + 1, j + 1, i, j + 1, i, j + 1},
                               {i, j + 1, i, j, i - 1, j}};
      for (const auto& s : sides) {
        const auto n = cell(s[4], s[5]);
        // This cell's extent less the neighbour's: below it and above it.
        if (n[1] <= 0 || n[0] >= e[1] || n[1] <= e[0]) {
          side_wall(s[0], s[1], s[2], s[3], e[0], e[1]);
          continue;
        }
        if (n[0] > e[0]) side_wall(s[0], s[1], s[2], s[3], e[0], n[0]);
        if (n[1] < e[1]) side_wall(s[0], s[1], s[2], s[3], n[1], e[1]);
      }
    }
  return m;
}

/// A 3 x 3 grid of cells, every one {0, base} but the middle {0, middle}.
std::vector<std::vector<std::array<double, 2>>> base_and_middle(double base, double middle) {
  std::vector<std::vector<std::array<double, 2>>> z(3, std::vector<std::array<double, 2>>(3, {0, base}));
  z[1][1] = {0, middle};
  return z;
}

/// A 1.3 m plinth (30 x 30) under a 15 x 15 tower 40 m high, one closed mesh: the ground is the plinth's.
Model plinth() {
  return cells_model({{0, 7.5, 22.5, 30}, {0, 7.5, 22.5, 30}, base_and_middle(1.3, 40)},
                     "POLYGON((0 0,30 0,30 30,0 30,0 0))", 900, 900);
}

/// A 12 m podium (40 x 35) with a 20 x 15 tower of 60 m on it, off centre.
Model podium() {
  return cells_model({{0, 10, 30, 40}, {0, 10, 25, 35}, base_and_middle(12, 60)}, "POLYGON((0 0,40 0,40 35,0 35,0 0))",
                     1400, 1400);
}

/// A 6 m podium (30 x 20) with a 10 x 10 tower of 50 m flush with its north-east corner: the tower's outer walls
/// and the podium's are one plane there.
Model podium_corner() {
  std::vector<std::vector<std::array<double, 2>>> z(2, std::vector<std::array<double, 2>>(2, {0, 6}));
  z[1][1] = {0, 50};
  return cells_model({{0, 20, 30}, {0, 10, 20}, z}, "POLYGON((0 0,30 0,30 20,0 20,0 0))", 600, 600);
}

/// Terraces: three storeys set back 5 m on every side (30 x 20, 4 / 8 / 16 m).
Model terraces() {
  std::vector<std::vector<std::array<double, 2>>> z(4, std::vector<std::array<double, 2>>(6, {0, 4}));
  for (int j = 1; j < 3; ++j)
    for (int i = 1; i < 5; ++i) z[j][i] = {0, (i >= 2 && i <= 3) ? 16.0 : 8.0};
  return cells_model({{0, 5, 10, 20, 25, 30}, {0, 5, 15, 20}, z}, "POLYGON((0 0,30 0,30 20,0 20,0 0))", 600, 600);
}

/// Two towers (10 x 10, 30 m and 45 m) on one 6 m base (50 x 20).
Model multi_tower() {
  std::vector<std::vector<std::array<double, 2>>> z(3, std::vector<std::array<double, 2>>(5, {0, 6}));
  z[1][1] = {0, 30};
  z[1][3] = {0, 45};
  return cells_model({{0, 5, 15, 35, 45, 50}, {0, 5, 15, 20}, z}, "POLYGON((0 0,50 0,50 20,0 20,0 0))", 1000, 1000);
}

/// An arcade: a 10 x 10 block, 12 m high, whose ground floor is set back 3 m from the street (y 0) behind two
/// 0.5 x 0.5 m pillars; the storeys above reach over the arcade. The footprint is the ground floor and the
/// pillars (70.5 m²), not the shadow (100 m²).
Model arcade() {
  const std::array<double, 2> up{3, 12}, full{0, 12};
  std::vector<std::vector<std::array<double, 2>>> z(3, std::vector<std::array<double, 2>>(5, up));
  z[0][1] = full;  // pillars
  z[0][3] = full;
  for (auto& e : z[2]) e = full;  // the ground floor behind the arcade
  return cells_model({{0, 2, 2.5, 7.5, 8, 10}, {0, 0.5, 3, 10}, z},
                     "MULTIPOLYGON(((0 3,10 3,10 10,0 10,0 3)),((2 0,2.5 0,2.5 0.5,2 0.5,2 0)),((7.5 0,8 0,8 0.5,7.5 0.5,7.5 0)))",
                     70.5, 100);
}

struct Family {
  const char* name;
  Model (*make)();
};

constexpr std::array<Family, 16> kFamilies{{{"eaves_open", eaves_open},
                                          {"eaves_soffit", eaves_soffit},
                                          {"slab_roof", slab_roof},
                                          {"cantilever", cantilever},
                                          {"balcony", balcony},
                                          {"stepped_ground", stepped_ground},
                                          {"stacked_boxes", stacked_boxes},
                                          {"stacked_overhang", stacked_overhang},
                                          {"stacked_corner", stacked_corner},
                                          {"disconnected", disconnected},
                                          {"plinth", plinth},
                                          {"podium", podium},
                                          {"podium_corner", podium_corner},
                                          {"terraces", terraces},
                                          {"multi_tower", multi_tower},
                                          {"arcade", arcade}}};

/// Whether three corners lie on one line.
bool collinear(const Point3& a, const Point3& b, const Point3& c) {
  const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z, vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
  return uy * vz - uz * vy == 0 && uz * vx - ux * vz == 0 && ux * vy - uy * vx == 0;
}

/// Convex faces fanned into triangles (corners shared bit for bit, orientation kept). A face with corners in
/// a line (a wall with the heights of its neighbours on its edges) is fanned from its centre instead, which
/// no corner lies in a line with.
std::vector<Ring3> triangles(const std::vector<Ring3>& faces) {
  std::vector<Ring3> out;
  for (const Ring3& f : faces) {
    bool straight = false;
    for (std::size_t k = 0; k < f.size(); ++k) straight |= collinear(f[k], f[(k + 1) % f.size()], f[(k + 2) % f.size()]);
    if (!straight) {
      for (std::size_t k = 1; k + 1 < f.size(); ++k) out.push_back({f[0], f[k], f[k + 1]});
      continue;
    }
    Point3 c{0, 0, 0};
    for (const Point3& p : f) c = {c.x + p.x / f.size(), c.y + p.y / f.size(), c.z + p.z / f.size()};
    for (std::size_t k = 0; k < f.size(); ++k) out.push_back({c, f[k], f[(k + 1) % f.size()]});
  }
  return out;
}

/// Triangle soup: shuffled, every other one (at random) flipped, corners jittered by up to 1e-4 m
/// (a tenth of the weld tolerance), as exporters write them.
std::vector<Ring3> soup(std::vector<Ring3> tris, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-1e-4, 1e-4);
  std::shuffle(tris.begin(), tris.end(), rng);
  for (Ring3& t : tris) {
    if (rng() % 2) std::swap(t[1], t[2]);
    for (Point3& p : t) p = {p.x + jitter(rng), p.y + jitter(rng), p.z + jitter(rng)};
  }
  return tris;
}

const char* writing_name(Writing w) { return w == Writing::Polygons ? "polygons" : w == Writing::Triangles ? "triangles" : "soup"; }

}  // namespace

std::vector<std::string> known_footprint_families() {
  std::vector<std::string> out;
  for (const Family& f : kFamilies) out.push_back(f.name);
  return out;
}

std::vector<KnownFootprint> known_footprints() {
  std::vector<KnownFootprint> out;
  unsigned seed = 21;
  for (const Family& fam : kFamilies) {
    const Model model = fam.make();
    for (Writing w : {Writing::Polygons, Writing::Triangles, Writing::Soup})
      for (bool floor : {false, true}) {
        std::vector<Ring3> faces;
        for (const Face& f : model.faces)
          if (floor || !f.ground) faces.push_back(f.ring);
        if (w != Writing::Polygons) faces = triangles(faces);
        if (w == Writing::Soup) faces = soup(std::move(faces), seed++);
        KnownFootprint k;
        k.family = fam.name;
        k.name = std::string(fam.name) + "_" + writing_name(w) + (floor ? "_floor" : "_open");
        k.writing = w;
        k.floor = floor;
        for (const Ring3& r : faces) k.mesh.add_face({r}, SurfaceKind::Unknown, 255);
        k.mesh.source_id = k.name;
        k.true_wkt = model.true_wkt;
        k.true_area_m2 = model.true_area_m2;
        k.shadow_area_m2 = model.shadow_area_m2;
        out.push_back(std::move(k));
      }
  }
  return out;
}

}  // namespace groundplan::test
