// SPDX-License-Identifier: MIT
// Footprints by surface decomposition (paper §4, issue 5).
//
// Pipeline per mesh, all on per-thread scratch buffers (issue 5 asks for >= 200k LoD2 buildings/s per
// core, i.e. a few microseconds each, so nothing here allocates once the buffers are warm, and hash
// tables are not even cleared: their slots carry a generation number, see GenTable):
//  1. Weld vertices within weld_tolerance_m: readers give every polygon its own copy of its corners
//     (bit for bit the same: one hash of the raw coordinates finds them), and triangle soup has no
//     connectivity at all (the paper's stated limitation: coordinates not seen before go to a grid of
//     16 x tol cells, the neighbouring cells probed only within tol of a side). One pass per ring
//     welds, takes the Newell normal and bounding box, and tells walls from the rest (no square root:
//     which edges a wall rises from is decided on squares).
//  2. Boundary-oriented half-edges per face ring (holes turned against the outer ring), grouped by
//     undirected welded edge. Faces written twice are resolved (same way: one kept; opposite ways:
//     a wall between two closed parts, both dropped). Edges seen by one facet only are split where
//     another such edge's end lies on them (T-junctions, frequent in CityGML LoD2), then regrouped.
//  3. Orientation: union-find with parity over manifold edges (two facets) makes every part's facets
//     agree; the part's signed volume, taken about a point at the part's lowest z, says which way is
//     out. The volume stays meaningful with an open bottom: the missing floor lies (nearly) in a plane
//     through that point, so it would have added (nearly) nothing.
//  4. Decomposition: facets within proxy_tolerance_deg of the vertical proxy normal are floor (normal
//     down) or ceiling (normal up) facets, the rest wall facets; patches are their connected sets.
//  5. Lower boundary: an edge is a footprint edge when a wall facet rises from it (the in-plane
//     direction into the facet points up) and no wall facet continues below it: the paper's local
//     minimum, decided per edge, so it does not depend on floors being present, whole or holed.
//     Not where a ceiling meets it (paper: "except the ceiling boundaries": parapets, penthouses),
//     nor a floor patch from which a wall goes down elsewhere (a soffit: an upper storey wider than
//     the one below on every side would otherwise give its shadow). Edges of two wall facets that
//     rise from it on opposite sides (parts sharing a wall) cancel.
//  6. Footprint edges, directed by the outward facet (building on the left), are chained into loops
//     over welded vertices; at a vertex with several ways on, the leftmost turn is taken (ties by
//     edge order), which keeps rings simple where parts touch at a corner. Chains that do not close
//     are not local-minimum loops (the edge of a soffit, a part standing on another) and are dropped.
//     Chains still open are chained again in plan view (endpoints within the weld tolerance in x, y
//     are one vertex): a bottom stepping at a vertical edge is continuous in plan (terraced sites).
//  7. Loops projected to 2D: counter-clockwise = outer ring, clockwise = hole; each hole goes to the
//     smallest outer ring of its own part that contains it. Parts whose outside cannot be told use
//     nesting depth instead.
//  8. When no loop closes, or a tenth or more of the lower boundary (plan length) lies in open chains
//     outside every loop and no higher than the loops (a model that is not watertight: SketchUp /
//     COLLADA exports whose walls stop short of each other or stand on roofs they share no edge
//     with), the loops do not say where the building stands: the footprint is its shadow, the exact
//     union of the facets' vertical projections (DecomposeParams::shadow_fallback; issue 5, Macky).
#include "footprint/decompose.h"

#include <groundplan/ground_plans.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kBad = kNone - 1;  // a vertex with NaN or infinite coordinates
/// A wall facet "rises" from an edge when the in-plane direction into it has at least this z
/// component (unit vectors): vertical edges (0) and edges of walls leaning < 0.6° are neither.
constexpr double kRise = 0.01;

struct V3 {
  double x = 0, y = 0, z = 0;
};
inline V3 operator-(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline double dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

enum : std::uint8_t { kFloor = 0, kCeiling = 1, kWall = 2, kSkipped = 255 };

struct FaceInfo {
  V3 n;                 // Newell normal of the outer ring as written (welded positions)
  double len = 0;       // |n| = twice the area
  V3 net;               // n less the holes' normals: twice the face's area vector (signed volume)
  V3 c;                 // a vertex of the face (its outer ring's first)
  V3 lo, hi;            // bounding box of the outer ring
  std::uint32_t uf = 0; // union-find parent
  std::uint8_t parity = 0;  // orientation relative to the parent: 1 = opposite
  std::int8_t sign = 1;     // +1: written orientation faces out; -1: flipped
  std::uint8_t cls = kSkipped;
};

struct HalfEdge {
  HalfEdge() {}  // left uninitialised: resize() for a mesh's half-edges writes nothing
  HalfEdge(std::uint32_t a_, std::uint32_t b_, std::uint32_t face_, std::int8_t up_) : a(a_), b(b_), face(face_), up(up_) {}
  std::uint32_t a, b;   // welded vertices, boundary orientation of the face as written
  std::uint32_t face;
  /// Whether a wall facet rises from this edge: +1 when the unit in-plane direction into the face
  /// has a z component above kRise, -1 below -kRise (it goes down), 0 otherwise and for non-walls.
  /// Orientation-independent.
  std::int8_t up;
};

struct DirEdge {
  std::uint32_t from, to, comp;
};

struct ExactEntry {
  std::uint32_t vertex, rep;  // a mesh vertex with these coordinates (bit for bit), their id
  std::uint32_t gen;
};

struct WeldEntry {
  std::int32_t kx, ky, kz;
  std::uint32_t rep;
  std::uint32_t gen;
};

struct FaceEntry {
  std::uint64_t hash;
  std::uint32_t face, first, count, rings;  // first: the welded outer ring in `canon`
  std::uint32_t gen;
};

struct Dup {
  std::uint32_t slot, face;
  bool fwd;
};

struct EdgeEntry {
  std::uint64_t key;    // smaller vertex << 32 | larger
  std::uint32_t group;
  std::uint32_t gen;
};

/// An open-addressing table kept across meshes: a slot is empty unless it carries the current
/// generation, so starting a mesh clears nothing (a few kilobytes of memset per building would
/// cost as much as the rest of a small one), and the mask covers only the slots this mesh needs.
template <class Entry>
struct GenTable {
  std::vector<Entry> slots;
  std::size_t mask = 0;
  std::uint32_t gen = 0;
  /// Room for `n` keys at most half full; returns the generation that marks this use's slots.
  std::uint32_t start(std::size_t n) {
    std::size_t size = 64;
    while (size < 2 * n) size <<= 1;
    if (slots.size() < size) slots.resize(size, Entry{});
    mask = size - 1;
    if (++gen == 0) {  // wrapped: every old mark must go
      for (Entry& e : slots) e.gen = 0;
      gen = 1;
    }
    return gen;
  }
  bool empty(std::size_t s) const { return slots[s].gen != gen; }
};

struct XEnd {
  double x, y, z;
  std::uint32_t v;
};

struct XId {
  double x;
  std::uint32_t id;
};

inline std::uint64_t mix64(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}


struct Workspace {
  std::vector<std::uint32_t> weld;      // mesh vertex -> welded id
  GenTable<EdgeEntry> edge_table;
  std::vector<V3> wpos;                 // welded positions, relative to the origin
  GenTable<WeldEntry> weld_table;
  GenTable<ExactEntry> exact_table;
  std::vector<XId> weld_sort;
  std::vector<std::uint32_t> distinct_of, distinct_weld;  // mesh vertex -> distinct point -> welded id
  std::vector<V3> distinct_pos;
  std::vector<FaceInfo> faces;
  std::vector<HalfEdge> halfedges, split_tmp;
  GenTable<FaceEntry> face_table;
  std::vector<std::uint32_t> canon;     // canonical welded outer rings, for duplicate faces
  std::vector<Dup> dups;
  std::vector<std::uint32_t> he_group, group_count, group_start, group_members, bucket_start;
  std::vector<std::uint32_t> ring_tmp, ring_buf;
  std::vector<std::uint32_t> he_next, he_max;  // group_edges(): chains per smaller vertex
  std::vector<std::uint32_t> cnt_buf;  // group sizes while grouping (only grows)
  std::vector<V3> comp_lo, comp_hi;
  std::vector<double> comp_vol, comp_area;
  std::vector<V3> comp_net;
  std::vector<std::int8_t> comp_sign;
  std::vector<std::uint32_t> comp_index;  // union-find root -> dense component id
  std::vector<std::uint32_t> face_comp;   // face -> dense component id
  std::vector<std::uint8_t> face_par;     // face -> orientation parity against its component
  std::vector<DirEdge> cand;
  std::vector<std::uint32_t> out_start, out_list;
  std::vector<std::uint8_t> used;
  std::vector<std::uint32_t> stamp, chain_v, chain_e;
  std::uint32_t stamp_gen = 0;
  std::vector<std::uint32_t> endpoints;
  std::vector<XEnd> xends;
  std::vector<std::uint32_t> open_he, end_seen;  // open_end_on_open_edge()
  std::uint32_t end_gen = 0;
  std::vector<std::uint32_t> plan_rep;  // plan-view merge of footprint-edge endpoints (rule 2)
  std::vector<std::uint32_t> open_edges;  // footprint edges left in chains that did not close
  std::vector<DirEdge> open_tmp;
  struct Loop {
    std::uint32_t comp;
    double zmax;               // highest vertex (relative to the origin)
    std::size_t first, count;  // into loop_pts
    double area;
    double minx, miny, maxx, maxy;
  };
  std::vector<Loop> loops;
  std::vector<Point2> loop_pts;  // relative to the origin
  std::vector<std::int32_t> poly_of_loop;
  std::vector<std::uint32_t> floor_uf;
  std::vector<std::uint8_t> hanging;
};

/// Half-edge h, of the undirected edge lo < hi, into its group (groups numbered in order of first
/// appearance; cnt counts each group's half-edges). The earlier half-edges with the same smaller
/// vertex are chained per vertex (head, next; hmax their larger vertex), a handful, so h finds its
/// group by walking that chain.
inline void group_half_edge(std::uint32_t h, std::uint32_t lo, std::uint32_t hi, std::uint32_t* head, std::uint32_t* next,
                            std::uint32_t* hmax, std::uint32_t* grp, std::uint32_t* cnt, std::uint32_t& ng) {
  std::uint32_t j = head[lo];
  while (j != kNone && hmax[j] != hi) j = next[j];
  std::uint32_t g;
  if (j == kNone) {
    g = ng++;
    cnt[g] = 0;
  } else {
    g = grp[j];
  }
  ++cnt[g];
  grp[h] = g;
  hmax[h] = hi;
  next[h] = head[lo];
  head[lo] = h;
}

Workspace& workspace() {
  thread_local Workspace ws;
  return ws;
}

std::uint32_t uf_find(FaceInfo* f, std::uint32_t i, std::uint8_t& parity) {
  parity = 0;
  std::uint32_t r = i;
  while (f[r].uf != r) {
    parity ^= f[r].parity;
    r = f[r].uf;
  }
  // Path compression keeping parities: walk again, pointing every node at the root.
  std::uint8_t p = parity;
  while (f[i].uf != r && f[i].uf != i) {
    std::uint32_t next = f[i].uf;
    std::uint8_t pi = f[i].parity;
    f[i].uf = r;
    f[i].parity = p;
    p ^= pi;
    i = next;
  }
  return r;
}

/// Shadow rings (outer or hole) smaller than this are dropped (rule 3). m².
constexpr double kShadowMinRing_m2 = 0.01;

double ring_area(const Ring& r) {
  double a = 0;
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) a += (r[j].x - r[i].x) * (r[j].y + r[i].y);
  return a / 2;
}

/// Point in ring (crossing number), ring relative coordinates.
bool inside(const Point2* ring, std::size_t n, Point2 p) {
  bool in = false;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Point2 &a = ring[i], &b = ring[j];
    if ((a.y > p.y) != (b.y > p.y)) {
      double x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (p.x < x) in = !in;
    }
  }
  return in;
}

class Decomposer {
 public:
  Decomposer(const Mesh& m, const DecomposeParams& p, Workspace& ws) : m_(m), p_(p), ws_(ws) {}

  DecomposeResult run(SurfaceDecomposition* dec) {
    DecomposeResult res;
    stats_ = &res.stats;
    if (!find_origin()) return res;
    build_faces();
    resolve_duplicates();
    if (stats_->faces_used == 0) return res;
    if (!ws_.dups.empty()) group_edges();  // else grouped in the ring pass, nothing dropped
    else finish_groups(ng_);
    if (split_t_junctions()) group_edges();
    orient();
    classify();
    find_hanging_floors();
    if (dec) fill_decomposition(*dec);
    collect_footprint_edges();
    chain_loops();
    make_polygons(res.polygons);
    if (p_.shadow_fallback && (res.polygons.empty() || open_outside_loops())) {
      res.polygons.clear();
      make_shadow(res.polygons);
    }
    return res;
  }

 private:
  const Mesh& m_;
  const DecomposeParams& p_;
  Workspace& ws_;
  DecomposeStats* stats_ = nullptr;
  V3 o_;
  double tol_ = 1e-3, tol2_ = 1e-6, inv_cell_ = 1, cos2_tol_ = 0;
  static constexpr double kCell = 16;  // weld grid cell, in weld tolerances
  bool grid_ = false;  // weld through the tolerance grid (vertices within tol of each other)
  std::size_t ring_len_ = 0;  // vertices in ring_buf
  std::uint32_t ng_ = 0;  // groups found by build_face_rings()
  std::size_t ncomp_ = 0;
  double lower_boundary_len_ = 0;  // plan length of all footprint edges (set when chains stay open)

  bool find_origin() {
    for (const Point3& q : m_.vertices)
      if (std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z)) {
        o_ = {q.x, q.y, q.z};
        return true;
      }
    return false;
  }

  // ---- 1. welding -------------------------------------------------------------------------------
  static std::size_t cell_hash(std::int32_t x, std::int32_t y, std::int32_t z) {
    std::uint64_t h = (std::uint64_t(std::uint32_t(x)) | std::uint64_t(std::uint32_t(y)) << 32) * 0x9E3779B97F4A7C15ULL;
    h ^= std::uint64_t(std::uint32_t(z)) * 0xC2B2AE3D27D4EB4FULL;
    return static_cast<std::size_t>(h ^ (h >> 32));
  }

  /// floor() without the libm call (x86-64 baseline has no roundsd); exact for |v| < 2^31.
  static double floor_fast(double v) {
    if (!(std::fabs(v) < 2.0e9)) return std::floor(v);
    const double t = static_cast<double>(static_cast<std::int64_t>(v));
    return t > v ? t - 1 : t;
  }

  /// The welded vertex in grid cell (cx, cy, cz) within tol of p, kNone if none.
  std::uint32_t probe(std::int32_t cx, std::int32_t cy, std::int32_t cz, const V3& p) const {
    const auto& T = ws_.weld_table;
    for (std::size_t h = cell_hash(cx, cy, cz) & T.mask;; h = (h + 1) & T.mask) {
      const WeldEntry& e = T.slots[h];
      if (e.gen != T.gen) return kNone;
      if (e.kx == cx && e.ky == cy && e.kz == cz) {
        const V3 d = ws_.wpos[e.rep] - p;
        if (dot(d, d) <= tol2_) return e.rep;
      }
    }
  }

  /// Welded id of mesh vertex vi, kBad for a non-finite one. Ids are given in order of first use.
  /// Without vertices within tol of each other (distinct_apart(): nearly always) a vertex is the
  /// distinct point its coordinates are (found before the pass), and that is all. Otherwise the grid
  /// welds (weld_vertex_grid). Both give the same ids when no two points lie within tol: the grid
  /// welds a point only to one within tol (by the same squared distance), so then every distinct
  /// point is its own vertex, numbered in order of first use.
  std::uint32_t weld_vertex(std::uint32_t vi) {
    if (!grid_) return weld_apart(vi);
    std::uint32_t& w = ws_.weld[vi];
    if (w != kNone) return w;
    return w = weld_vertex_grid(vi);
  }

  /// Hash of a point's coordinate bits.
  static std::size_t bits_hash(std::uint64_t bx, std::uint64_t by, std::uint64_t bz) {
    return static_cast<std::size_t>(mix64(bx ^ (by * 0x9E3779B97F4A7C15ULL) ^ (bz * 0xC2B2AE3D27D4EB4FULL)));
  }

  /// Distinct points of the mesh (bit for bit; non-finite ones kBad) into distinct_of / distinct_pos,
  /// and whether no two of them lie within tol (then the grid is not needed). Readers give every
  /// polygon its own copies of shared corners, bit for bit the same: one hash of the raw coordinates
  /// finds those. Pairs are looked for in x order; those closer than 2 tol in x are measured as
  /// probe() measures them (|dx| > 2 tol gives a squared distance above tol^2 even rounded). Comparing
  /// bits finds what comparing values did in the grid: +0/-0 copies differ in bits but lie at
  /// distance 0 (then the grid welds them), and non-finite points are kBad either way.
  bool distinct_apart() {
    const std::size_t nv = m_.vertices.size();
    auto& X = ws_.exact_table;
    X.start(nv);
    auto& of = ws_.distinct_of;
    auto& pos = ws_.distinct_pos;
    of.resize(nv);
    pos.clear();
    static_assert(sizeof(Point3) == 24);
    const Point3* MV = m_.vertices.data();
    std::uint32_t* OF = of.data();
    ExactEntry* XS = X.slots.data();
    const std::size_t xmask = X.mask;
    const std::uint32_t xgen = X.gen;
    constexpr std::uint64_t kExp = 0x7ffULL << 52;  // all ones: infinite or NaN (std::isfinite false)
    for (std::uint32_t vi = 0; vi < nv; ++vi) {
      const Point3& q = MV[vi];
      std::uint64_t bx, by, bz;
      std::memcpy(&bx, &q.x, 8), std::memcpy(&by, &q.y, 8), std::memcpy(&bz, &q.z, 8);
      if ((bx & kExp) == kExp || (by & kExp) == kExp || (bz & kExp) == kExp) {
        OF[vi] = kBad;
        continue;
      }
      std::size_t es = bits_hash(bx, by, bz) & xmask;
      for (;; es = (es + 1) & xmask) {
        const ExactEntry& e = XS[es];
        if (e.gen != xgen) {
          const std::uint32_t d = static_cast<std::uint32_t>(pos.size());
          XS[es] = ExactEntry{vi, d, xgen};
          pos.push_back(V3{q.x - o_.x, q.y - o_.y, q.z - o_.z});
          OF[vi] = d;
          break;
        }
        std::uint64_t ex, ey, ez;  // bit for bit, as memcmp of the three doubles
        const Point3& r = MV[e.vertex];
        std::memcpy(&ex, &r.x, 8), std::memcpy(&ey, &r.y, 8), std::memcpy(&ez, &r.z, 8);
        if (ex == bx && ey == by && ez == bz) {
          OF[vi] = e.rep;
          break;
        }
      }
    }
    ws_.distinct_weld.assign(pos.size(), kNone);
    const std::size_t n = pos.size();
    if (n < 2) return true;
    auto& xs = ws_.weld_sort;
    xs.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) xs[i] = XId{pos[i].x, i};
    std::sort(xs.begin(), xs.end(), [](const XId& u, const XId& v) { return u.x < v.x; });
    const double w = 2 * tol_;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const double lim = xs[i].x + w;
      for (std::size_t j = i + 1; j < n && xs[j].x <= lim; ++j) {
        const V3 d = pos[xs[j].id] - pos[xs[i].id];
        if (dot(d, d) <= tol2_) return false;
      }
    }
    return true;
  }

  /// The grid weld (vertices within tol of each other): exact copies through one hash of the raw
  /// coordinates, points not seen before through the tolerance grid (weld_new). Grid cells are
  /// kCell x tol wide, so a point needs the neighbouring cell on an axis only within tol of that
  /// side (mostly one probe).
  std::uint32_t weld_vertex_grid(std::uint32_t vi) {
    const Point3& q = m_.vertices[vi];
    std::uint64_t bx, by, bz;
    std::memcpy(&bx, &q.x, 8), std::memcpy(&by, &q.y, 8), std::memcpy(&bz, &q.z, 8);
    auto& X = ws_.exact_table;
    std::size_t es = bits_hash(bx, by, bz) & X.mask;
    for (;; es = (es + 1) & X.mask) {
      const ExactEntry& e = X.slots[es];
      if (e.gen != X.gen) break;
      if (std::memcmp(&m_.vertices[e.vertex], &q, sizeof(Point3)) == 0) return e.rep;
    }
    const std::uint32_t w = weld_new(q);
    X.slots[es] = ExactEntry{vi, w, X.gen};
    return w;
  }

  /// Welded id of a point not seen before (by its exact coordinates).
  std::uint32_t weld_new(const Point3& q) {
    std::uint32_t w;
    if (!(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z))) return kBad;
    const V3 p{q.x - o_.x, q.y - o_.y, q.z - o_.z};
    const double tx = p.x * inv_cell_, ty = p.y * inv_cell_, tz = p.z * inv_cell_;
    const double fx = floor_fast(tx), fy = floor_fast(ty), fz = floor_fast(tz);
    // Cells beyond int32 range (a mesh kilometres across with a tiny tolerance) just clamp: the
    // exact distance test keeps welding correct, only the hashing gets slower.
    auto clampi = [](double v) { return static_cast<std::int32_t>(std::clamp(v, -2.0e9, 2.0e9)); };
    const std::int32_t kx = clampi(fx), ky = clampi(fy), kz = clampi(fz);
    std::uint32_t found = probe(kx, ky, kz, p);
    if (found != kNone) return found;
    auto side = [](double frac) { return frac < 1 / kCell ? -1 : frac > 1 - 1 / kCell ? 1 : 0; };
    const std::int32_t sx = side(tx - fx), sy = side(ty - fy), sz = side(tz - fz);
    if (const int near = (sx != 0) | (sy != 0) << 1 | (sz != 0) << 2) {
      for (int c = 1; c < 8; ++c) {
        if (c & ~near) continue;
        found = probe(kx + ((c & 1) ? sx : 0), ky + ((c & 2) ? sy : 0), kz + ((c & 4) ? sz : 0), p);
        if (found != kNone) return found;
      }
    }
    w = static_cast<std::uint32_t>(ws_.wpos.size());
    ws_.wpos.push_back(p);
    auto& T = ws_.weld_table;
    std::size_t h = cell_hash(kx, ky, kz) & T.mask;
    while (!T.empty(h)) h = (h + 1) & T.mask;
    T.slots[h] = WeldEntry{kx, ky, kz, w, T.gen};
    return w;
  }

  /// Welded vertices of ring r into ring_tmp, consecutive repeats (and the closing repeat) removed.
  /// False when the ring has an index out of range or a non-finite vertex.
  bool welded_ring(std::uint32_t r) {
    auto& out = ws_.ring_tmp;
    out.clear();
    const std::uint32_t a = m_.ring_offsets[r], b = m_.ring_offsets[r + 1];
    for (std::uint32_t k = a; k < b; ++k) {
      const std::uint32_t vi = m_.indices[k];
      if (vi >= m_.vertices.size()) return false;
      const std::uint32_t w = weld_vertex(vi);
      if (w == kBad) return false;
      if (out.empty() || out.back() != w) out.push_back(w);
    }
    while (out.size() > 1 && out.back() == out.front()) out.pop_back();
    return true;
  }

  /// Welded id of mesh vertex vi while no two vertices lie within tol (grid_ false): its distinct
  /// point's id, given in order of first use.
  std::uint32_t weld_apart(std::uint32_t vi) {
    const std::uint32_t d = ws_.distinct_of[vi];
    if (d == kBad) return kBad;
    std::uint32_t& f = ws_.distinct_weld[d];
    if (f == kNone) {
      f = static_cast<std::uint32_t>(ws_.wpos.size());
      ws_.wpos.push_back(ws_.distinct_pos[d]);  // reserved: data() does not move
    }
    return f;
  }

  // ---- 2. faces and half-edges ------------------------------------------------------------------
  /// Remembers the face's welded outer ring (ring_buf); a face seen before with the same ring (any
  /// start, either direction) and ring count is noted in `dups` for resolve_duplicates(), with
  /// `fwd` telling whether it runs the way the first one does. The hash does not depend on start
  /// or direction, so nothing is rotated unless two hashes meet.
  void note_face(std::uint32_t f, std::uint32_t ring_count) {
    const std::uint32_t* r = ws_.ring_buf.data();
    const std::size_t k = ring_len_;
    std::uint64_t sum = 0, x = 0;
    for (std::size_t i = 0; i < k; ++i) {
      const std::uint64_t m = (r[i] + 1) * 0x9E3779B97F4A7C15ULL;
      sum += m ^ (m >> 29);
      x ^= m;
    }
    const std::uint64_t h = mix64(sum ^ (x << 1) ^ (k * 0xC2B2AE3D27D4EB4FULL + ring_count));
    auto& T = ws_.face_table;
    for (std::size_t s = h & T.mask;; s = (s + 1) & T.mask) {
      FaceEntry& e = T.slots[s];
      if (e.gen != T.gen) {
        e = FaceEntry{h, f, static_cast<std::uint32_t>(ws_.canon.size()), static_cast<std::uint32_t>(k), ring_count, T.gen};
        ws_.canon.insert(ws_.canon.end(), r, r + k);
        return;
      }
      if (e.hash != h || e.count != k || e.rings != ring_count) continue;
      const int dir = same_cycle(ws_.canon.data() + e.first, r, k);
      if (dir == 0) continue;
      if (ws_.dups.empty() || ws_.dups.back().slot != s || ws_.dups.back().face != e.face)
        ws_.dups.push_back(Dup{static_cast<std::uint32_t>(s), e.face, true});
      ws_.dups.push_back(Dup{static_cast<std::uint32_t>(s), f, dir > 0});
      return;
    }
  }

  /// +1 when ring b is ring a from another start, -1 when it is a reversed, 0 otherwise (k >= 3).
  static int same_cycle(const std::uint32_t* a, const std::uint32_t* b, std::size_t k) {
    std::size_t j = 0;
    while (j < k && a[j] != b[0]) ++j;
    if (j == k) return 0;
    bool fwd = true, bwd = true;
    for (std::size_t i = 1; i < k && (fwd || bwd); ++i) {
      fwd = fwd && b[i] == a[(j + i) % k];
      bwd = bwd && b[i] == a[(j + k - i) % k];
    }
    return fwd ? 1 : bwd ? -1 : 0;
  }

  /// Faces written more than once. Copies running opposite ways are a face between two solids of one
  /// mesh (each part closed on its own): both go, and the parts merge into one solid. Copies running
  /// the same way are one face written twice (exporters do it): one stays. Either would otherwise
  /// make the edges non-manifold and cancel the part's volume.
  void resolve_duplicates() {
    if (ws_.dups.empty()) return;
    auto& d = ws_.dups;
    std::sort(d.begin(), d.end(), [](const Dup& x, const Dup& y) { return x.slot < y.slot || (x.slot == y.slot && x.face < y.face); });
    d.erase(std::unique(d.begin(), d.end(), [](const Dup& x, const Dup& y) { return x.slot == y.slot && x.face == y.face; }),
            d.end());
    for (std::size_t i = 0; i < d.size();) {
      std::size_t j = i;
      std::size_t nf = 0, nb = 0;
      while (j < d.size() && d[j].slot == d[i].slot) (d[j].fwd ? nf : nb) += 1, ++j;
      std::size_t cancel = std::min(nf, nb), keep = nf + nb > 2 * cancel ? 1 : 0;
      std::size_t cf = cancel, cb = cancel;
      for (std::size_t k = i; k < j; ++k) {
        std::size_t& c = d[k].fwd ? cf : cb;
        if (c > 0) {
          --c;
        } else if (keep > 0) {
          --keep;
          continue;
        }
        ws_.faces[d[k].face].cls = kSkipped;
        ++stats_->duplicate_faces;
        --stats_->faces_used;
      }
      i = j;
    }
    auto& he = ws_.halfedges;
    he.erase(std::remove_if(he.begin(), he.end(), [&](const HalfEdge& h) { return ws_.faces[h.face].cls == kSkipped; }),
             he.end());
  }

  void build_faces() {
    tol_ = std::max(p_.weld_tolerance_m, 1e-9);
    tol2_ = tol_ * tol_;
    inv_cell_ = 1.0 / (kCell * tol_);
    const double cos_tol = std::cos(std::clamp(p_.proxy_tolerance_deg, 0.0, 89.0) * kPi / 180.0);
    cos2_tol_ = cos_tol * cos_tol;
    ws_.wpos.clear();
    grid_ = !distinct_apart();
    ws_.wpos.reserve(ws_.distinct_pos.size());
    if (grid_) {
      ws_.weld.assign(m_.vertices.size(), kNone);
      const std::size_t distinct = std::min(m_.indices.size(), m_.vertices.size());
      ws_.weld_table.start(distinct);
      ws_.exact_table.start(distinct);
    }
    if (ws_.ring_buf.size() < m_.indices.size()) ws_.ring_buf.resize(m_.indices.size());
    ws_.faces.assign(m_.faces.size(), FaceInfo{});
    ws_.face_table.start(m_.faces.size());
    ws_.canon.clear();
    ws_.dups.clear();
    ws_.halfedges.clear();
    ws_.halfedges.reserve(m_.indices.size());
    if (grid_) build_face_rings<true>();
    else build_face_rings<false>();
    stats_->vertices_welded = ws_.wpos.size();
  }

  /// One pass per ring (outer, then holes) that welds, takes the Newell normal and bounding box
  /// (repeated vertices add exact zeros to the normal), notes the face for duplicates, and makes the
  /// boundary-oriented half-edges and groups them by undirected welded edge as they come (groups
  /// numbered in order of first appearance; the earlier half-edges with the same smaller vertex are
  /// chained per vertex, a handful). Without the grid a vertex is its distinct point, numbered in
  /// order of first use. The groups are final unless a face is dropped as a duplicate (then run()
  /// groups again, group_edges()).
  template <bool Grid>
  void build_face_rings() {
    const std::size_t nrings = m_.ring_count();
    const MeshFace* MF = m_.faces.data();
    FaceInfo* FI = ws_.faces.data();
    const std::uint32_t nf = static_cast<std::uint32_t>(m_.faces.size());
    const std::uint32_t* idx = m_.indices.data();
    const std::uint32_t* ro = m_.ring_offsets.data();
    const std::size_t nv = m_.vertices.size();
    const std::size_t npos = ws_.distinct_pos.size();
    const std::uint32_t* of = ws_.distinct_of.data();
    std::uint32_t* dw = ws_.distinct_weld.data();
    const V3* dpos = ws_.distinct_pos.data();
    if (!Grid) ws_.wpos.resize(npos);  // grid: weld_new() appends (reserved for npos: data() stays)
    V3* W = ws_.wpos.data();
    std::uint32_t nw = 0;
    std::uint32_t* out = ws_.ring_buf.data();
    const std::size_t maxh = m_.indices.size();
    ws_.halfedges.resize(maxh);
    HalfEdge* HE = ws_.halfedges.data();
    std::uint32_t nh = 0, ng = 0;
    auto& headv = ws_.bucket_start;
    headv.assign(npos, kNone);
    std::uint32_t* head = headv.data();
    if (ws_.he_next.size() < maxh) ws_.he_next.resize(maxh), ws_.he_max.resize(maxh), ws_.he_group.resize(maxh);
    if (ws_.cnt_buf.size() < maxh) ws_.cnt_buf.resize(maxh);
    std::uint32_t* next = ws_.he_next.data();
    std::uint32_t* hmax = ws_.he_max.data();
    std::uint32_t* grp = ws_.he_group.data();
    std::uint32_t* cnt = ws_.cnt_buf.data();
    // Ring r's welded vertices into out (repeats removed), Newell normal, box.
    // Welded id of mesh vertex vi (kBad for an index out of range or a non-finite vertex); without
    // the grid: its distinct point's id, given in order of first use (nwl: ids given so far).
    auto weld = [&](std::uint32_t vi, std::uint32_t& nwl) -> std::uint32_t {
      if (vi >= nv) return kBad;
      if constexpr (Grid) {
        return weld_vertex(vi);
      } else {
        const std::uint32_t d = of[vi];
        if (d == kBad) return kBad;
        std::uint32_t w = dw[d];
        if (w == kNone) dw[d] = w = nwl, W[nwl++] = dpos[d];
        return w;
      }
    };
    // Accumulators are locals (written out at the end): stores through W, out and dw could alias the
    // caller's variables and would keep them in memory.
    auto ring = [&](std::uint32_t r, V3& n_out, V3& lo_out, V3& hi_out, std::size_t& len_out) -> bool {
      std::size_t len = 0;
      std::uint32_t nwl = nw;
      V3 n{}, lo, hi;
      const std::uint32_t a = ro[r], b = ro[r + 1];
      bool ok = true;
      if (a < b) {
        V3 first, prev;
        {
          const std::uint32_t w = weld(idx[a], nwl);
          if (w == kBad) {
            len_out = 0;
            n_out = V3{};
            return false;
          }
          first = prev = lo = hi = W[w];
          out[len++] = w;
        }
        for (std::uint32_t k = a + 1; k < b; ++k) {
          const std::uint32_t w = weld(idx[k], nwl);
          if (w == kBad) {
            ok = false;
            break;
          }
          const V3 p = W[w];
          n.x += (prev.y - p.y) * (prev.z + p.z);
          n.y += (prev.z - p.z) * (prev.x + p.x);
          n.z += (prev.x - p.x) * (prev.y + p.y);
          lo.x = std::min(lo.x, p.x), lo.y = std::min(lo.y, p.y), lo.z = std::min(lo.z, p.z);
          hi.x = std::max(hi.x, p.x), hi.y = std::max(hi.y, p.y), hi.z = std::max(hi.z, p.z);
          prev = p;
          if (out[len - 1] != w) out[len++] = w;
        }
        if (ok) {
          n.x += (prev.y - first.y) * (prev.z + first.z);
          n.y += (prev.z - first.z) * (prev.x + first.x);
          n.z += (prev.x - first.x) * (prev.y + first.y);
          while (len > 1 && out[len - 1] == out[0]) --len;
        }
      }
      nw = nwl;
      len_out = len;
      n_out = n;
      lo_out = lo;
      hi_out = hi;
      return ok;
    };
    // The ring's half-edges (reversed for a hole running with the outer ring), each into its group.
    auto edges = [&](std::uint32_t f, std::size_t k, const V3 n, const double len2, bool wall, bool reverse) {
      std::uint32_t h = nh, g_n = ng;
      for (std::size_t i = 0; i < k; ++i) {
        std::uint32_t a = out[i], b = out[i + 1 < k ? i + 1 : 0];
        if (reverse) std::swap(a, b);
        HE[h] = HalfEdge{a, b, f, wall ? rise(W, n, len2, a, b) : std::int8_t{0}};
        group_half_edge(h, std::min(a, b), std::max(a, b), head, next, hmax, grp, cnt, g_n);
        ++h;
      }
      nh = h;
      ng = g_n;
    };
    V3 n, lo, hi, nh3, hlo, hhi;
    std::size_t len = 0;
    for (std::uint32_t f = 0; f < nf; ++f) {
      const MeshFace& mf = MF[f];
      FaceInfo& fi = FI[f];
      fi.uf = f;
      if (mf.kind == SurfaceKind::FootPrint || mf.kind == SurfaceKind::RoofEdge) continue;
      if (mf.ring_count == 0 || std::size_t(mf.first_ring) + mf.ring_count > nrings) continue;
      if (!ring(mf.first_ring, n, lo, hi, len) || len < 3) continue;
      const double len2 = dot(n, n);
      if (!(len2 > 1e-24)) continue;  // zero area: no orientation, no class
      ring_len_ = len;
      note_face(f, mf.ring_count);
      fi.n = n;
      fi.len = std::sqrt(len2);
      fi.net = n;
      fi.c = W[out[0]];
      fi.lo = lo;
      fi.hi = hi;
      const bool wall = n.z * n.z < cos2_tol_ * len2;
      fi.cls = wall ? kWall : kFloor;
      ++stats_->faces_used;
      edges(f, len, n, len2, wall, false);
      for (std::uint32_t r = mf.first_ring + 1; r < mf.first_ring + mf.ring_count; ++r) {
        if (!ring(r, nh3, hlo, hhi, len) || len < 3) continue;
        const bool same = dot(nh3, n) > 0;
        fi.net = same ? fi.net - nh3 : V3{fi.net.x + nh3.x, fi.net.y + nh3.y, fi.net.z + nh3.z};
        edges(f, len, n, len2, wall, same);
      }
    }
    ring_len_ = 0;
    if (!Grid) ws_.wpos.resize(nw);
    ws_.halfedges.resize(nh);
    ng_ = ng;
  }

  /// Groups from he_group and cnt_buf (ng groups): group_count, group_start, group_members.
  void finish_groups(std::uint32_t ng) {
    const std::uint32_t* cnt = ws_.cnt_buf.data();
    ws_.group_count.assign(cnt, cnt + ng);
    sort_group_members(ng);
  }

  /// group_start and group_members (counting sort of the half-edges by he_group) from group_count.
  void sort_group_members(std::uint32_t ng) {
    const std::size_t nh = ws_.halfedges.size();
    const std::uint32_t* cnt = ws_.group_count.data();
    auto& start = ws_.group_start;
    start.resize(ng + 1);
    std::uint32_t* st = start.data();
    st[0] = 0;
    for (std::size_t g = 0; g < ng; ++g) st[g + 1] = st[g] + cnt[g];
    auto& cursor = ws_.bucket_start;
    cursor.assign(start.begin(), start.end() - 1);
    std::uint32_t* cur = cursor.data();
    ws_.group_members.resize(nh);
    std::uint32_t* mem = ws_.group_members.data();
    const std::uint32_t* grp = ws_.he_group.data();
    for (std::uint32_t i = 0; i < nh; ++i) mem[cur[grp[i]]++] = i;
  }


  /// HalfEdge::up of a wall facet with Newell normal n (|n|^2 = len2) along a -> b: the sign of
  /// (n x d).z / (|n| |d|) beyond +-kRise, decided on squares (no square root, no division).
  static std::int8_t rise(const V3* W, const V3& n, double len2, std::uint32_t a, std::uint32_t b) {
    const V3 d = W[b] - W[a];
    const double c = n.x * d.y - n.y * d.x;  // (n x d).z
    if (!(c * c > kRise * kRise * len2 * dot(d, d))) return 0;
    return c > 0 ? 1 : -1;
  }

  /// Half-edges grouped by undirected welded edge, groups numbered in order of first appearance:
  /// the earlier half-edges with the same smaller vertex are chained per vertex (a handful), so a
  /// half-edge finds its group by walking that chain. Then group_members in group order by a
  /// counting sort.
  void group_edges() {
    const std::size_t nh = ws_.halfedges.size(), nv = ws_.wpos.size();
    auto& head = ws_.bucket_start;  // per smaller vertex: latest half-edge with it, kNone if none
    head.assign(nv, kNone);
    ws_.he_next.resize(nh);
    ws_.he_max.resize(nh);
    ws_.he_group.resize(nh);
    std::uint32_t* H0 = head.data();
    std::uint32_t* next = ws_.he_next.data();
    std::uint32_t* hmax = ws_.he_max.data();
    std::uint32_t* grp = ws_.he_group.data();
    auto& count = ws_.group_count;
    count.resize(nh);  // at most one group per half-edge
    std::uint32_t* cnt = count.data();
    std::uint32_t ng = 0;
    const HalfEdge* H = ws_.halfedges.data();
    for (std::uint32_t i = 0; i < nh; ++i)
      group_half_edge(i, std::min(H[i].a, H[i].b), std::max(H[i].a, H[i].b), H0, next, hmax, grp, cnt, ng);
    count.resize(ng);
    sort_group_members(ng);
  }

  // ---- T-junctions ------------------------------------------------------------------------------
  /// Splits every edge seen by one facet at the ends of other such edges lying on it (within tol).
  /// Returns whether anything was split (then the edges must be regrouped).
  bool split_t_junctions() {
    // Nearly every mesh has none: a look with the split's own test first (open_end_on_open_edge),
    // and only where an end lies on an edge the split as it always was.
    if (!open_end_on_open_edge()) return false;
    auto& ends = ws_.xends;
    ends.clear();
    const std::size_t ng = ws_.group_count.size();
    const auto& P = ws_.wpos;
    for (std::size_t g = 0; g < ng; ++g) {
      if (ws_.group_count[g] != 1) continue;
      const HalfEdge& h = ws_.halfedges[ws_.group_members[ws_.group_start[g]]];
      ends.push_back(XEnd{P[h.a].x, P[h.a].y, P[h.a].z, h.a});
      ends.push_back(XEnd{P[h.b].x, P[h.b].y, P[h.b].z, h.b});
    }
    std::sort(ends.begin(), ends.end(), [](const XEnd& u, const XEnd& v) { return u.x < v.x || (u.x == v.x && u.v < v.v); });
    ends.erase(std::unique(ends.begin(), ends.end(), [](const XEnd& u, const XEnd& v) { return u.v == v.v; }), ends.end());

    // Most meshes have none: look first (boxes of the edges against the sorted ends), split after.
    auto lies_on_some_edge = [&](const HalfEdge& h) {
      const V3 &A = P[h.a], &B = P[h.b];
      const double xlo = std::min(A.x, B.x) - tol_, xhi = std::max(A.x, B.x) + tol_;
      const double ylo = std::min(A.y, B.y) - tol_, yhi = std::max(A.y, B.y) + tol_;
      const double zlo = std::min(A.z, B.z) - tol_, zhi = std::max(A.z, B.z) + tol_;
      auto it = std::lower_bound(ends.begin(), ends.end(), xlo, [](const XEnd& u, double x) { return u.x < x; });
      for (; it != ends.end() && it->x <= xhi; ++it)
        if (it->y >= ylo && it->y <= yhi && it->z >= zlo && it->z <= zhi && it->v != h.a && it->v != h.b) return true;
      return false;
    };
    bool candidate = false;
    for (std::size_t g = 0; g < ng && !candidate; ++g)
      candidate = ws_.group_count[g] == 1 && lies_on_some_edge(ws_.halfedges[ws_.group_members[ws_.group_start[g]]]);
    if (!candidate) return false;
    auto& out = ws_.split_tmp;
    out.clear();
    bool any = false;
    struct Hit {
      double t;
      std::uint32_t v;
    };
    Hit hits[64];
    const double tol2 = tol_ * tol_;
    for (std::size_t i = 0; i < ws_.halfedges.size(); ++i) {
      const HalfEdge h = ws_.halfedges[i];
      if (ws_.group_count[ws_.he_group[i]] != 1) {
        out.push_back(h);
        continue;
      }
      const V3 &A = P[h.a], &B = P[h.b];
      const V3 d = B - A;
      const double L2 = dot(d, d);
      int nhits = 0;
      const double xlo = std::min(A.x, B.x) - tol_, xhi = std::max(A.x, B.x) + tol_;
      auto it = std::lower_bound(ends.begin(), ends.end(), xlo, [](const XEnd& u, double x) { return u.x < x; });
      for (; it != ends.end() && it->x <= xhi && nhits < 64; ++it) {
        const std::uint32_t v = it->v;
        if (v == h.a || v == h.b) continue;
        const V3 ap = P[v] - A;
        const double t = dot(ap, d) / L2;
        if (!(t > 0) || !(t < 1)) continue;
        const V3 off{ap.x - t * d.x, ap.y - t * d.y, ap.z - t * d.z};
        if (dot(off, off) > tol2) continue;
        hits[nhits++] = Hit{t, v};
      }
      if (nhits == 0) {
        out.push_back(h);
        continue;
      }
      any = true;
      stats_->t_junction_splits += nhits;
      std::sort(hits, hits + nhits, [](const Hit& x, const Hit& y) { return x.t < y.t || (x.t == y.t && x.v < y.v); });
      const FaceInfo& fi = ws_.faces[h.face];
      std::uint32_t prev = h.a;
      for (int k = 0; k <= nhits; ++k) {
        const std::uint32_t next = k < nhits ? hits[k].v : h.b;
        if (next == prev) continue;
        out.push_back(HalfEdge{prev, next, h.face, fi.cls == kWall ? rise(P.data(), fi.n, fi.len * fi.len, prev, next) : std::int8_t{0}});
        prev = next;
      }
    }
    if (any) ws_.halfedges.swap(out);
    return any;
  }

  /// Whether some end of an edge seen by one facet lies on another such edge by the split's test
  /// (x within the edge's x range widened by tol, then 0 < t < 1 and squared offset within tol^2):
  /// exactly when the split would split something. Fewer than two such edges: never. The ends (each
  /// vertex once) are tried against every edge when there are few (a closed part without its ground
  /// has its bottom ring), else in x order from a binary search.
  bool open_end_on_open_edge() {
    const std::size_t ng = ws_.group_count.size();
    const V3* P = ws_.wpos.data();
    auto& edges = ws_.open_he;
    edges.clear();
    auto& ends = ws_.weld_sort;  // (x, vertex), each vertex once
    ends.clear();
    auto& seen = ws_.end_seen;
    if (seen.size() < ws_.wpos.size()) seen.resize(ws_.wpos.size(), 0);
    if (++ws_.end_gen == 0) {
      std::fill(seen.begin(), seen.end(), 0);
      ws_.end_gen = 1;
    }
    const std::uint32_t gen = ws_.end_gen;
    const std::uint32_t* cnt = ws_.group_count.data();
    const std::uint32_t* st = ws_.group_start.data();
    const std::uint32_t* mem = ws_.group_members.data();
    const HalfEdge* H = ws_.halfedges.data();
    for (std::size_t g = 0; g < ng; ++g) {
      if (cnt[g] != 1) continue;
      const HalfEdge& h = H[mem[st[g]]];
      edges.push_back(mem[st[g]]);
      if (seen[h.a] != gen) seen[h.a] = gen, ends.push_back(XId{P[h.a].x, h.a});
      if (seen[h.b] != gen) seen[h.b] = gen, ends.push_back(XId{P[h.b].x, h.b});
    }
    const std::size_t ne = edges.size(), nx = ends.size();
    if (ne < 2) return false;
    const double tol2 = tol_ * tol_;
    const XId* E = ends.data();
    const bool sorted = ne * nx > 1024;
    if (sorted) std::sort(ends.begin(), ends.end(), [](const XId& u, const XId& v) { return u.x < v.x; });
    for (std::size_t i = 0; i < ne; ++i) {
      const HalfEdge& h = H[edges[i]];
      const V3 &A = P[h.a], &B = P[h.b];
      const V3 d = B - A;
      const double L2 = dot(d, d);
      const double xlo = std::min(A.x, B.x) - tol_, xhi = std::max(A.x, B.x) + tol_;
      std::size_t j = 0, stop = nx;
      if (sorted) j = std::lower_bound(E, E + nx, xlo, [](const XId& u, double x) { return u.x < x; }) - E;
      for (; j < stop; ++j) {
        const double x = E[j].x;
        if (!(x <= xhi)) {
          if (sorted) break;
          continue;
        }
        if (!(x >= xlo)) continue;
        const std::uint32_t v = E[j].id;
        if (v == h.a || v == h.b) continue;
        const V3 ap = P[v] - A;
        const double t = dot(ap, d) / L2;
        if (!(t > 0) || !(t < 1)) continue;
        const V3 off{ap.x - t * d.x, ap.y - t * d.y, ap.z - t * d.z};
        if (dot(off, off) > tol2) continue;
        return true;
      }
    }
    return false;
  }

  // ---- 3. orientation ---------------------------------------------------------------------------
  void orient() {
    FaceInfo* F = ws_.faces.data();
    const std::size_t ng = ws_.group_count.size();
    const std::uint32_t* cnt = ws_.group_count.data();
    const std::uint32_t* st = ws_.group_start.data();
    const std::uint32_t* mem = ws_.group_members.data();
    const HalfEdge* H = ws_.halfedges.data();
    std::size_t nonmanifold = 0;
    for (std::size_t g = 0; g < ng; ++g) {
      const std::uint32_t c = cnt[g];
      nonmanifold += c > 2;
      if (c != 2) continue;
      const HalfEdge& h1 = H[mem[st[g]]];
      const HalfEdge& h2 = H[mem[st[g] + 1]];
      if (h1.face == h2.face) continue;
      // Consistent neighbours run the shared edge in opposite directions.
      const std::uint8_t rel = h1.a == h2.a ? 1 : 0;
      std::uint8_t p1, p2;
      const std::uint32_t r1 = uf_find(F, h1.face, p1), r2 = uf_find(F, h2.face, p2);
      if (r1 == r2) continue;  // already joined (a conflict here means a non-orientable patch: ignored)
      F[r2].uf = r1;
      F[r2].parity = static_cast<std::uint8_t>(p1 ^ p2 ^ rel);
    }
    stats_->nonmanifold_edges += nonmanifold;
    // Dense component ids and parities, bounding boxes, then signed volumes about each part's low point.
    const std::size_t nf = ws_.faces.size();
    ws_.comp_index.assign(nf, kNone);
    ws_.face_comp.resize(nf);
    ws_.face_par.resize(nf);
    std::uint32_t* cidx = ws_.comp_index.data();
    std::uint32_t* fcomp = ws_.face_comp.data();
    std::uint8_t* fpar = ws_.face_par.data();
    ws_.comp_lo.clear();
    ws_.comp_hi.clear();
    ncomp_ = 0;
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (std::uint32_t f = 0; f < nf; ++f) {
      if (F[f].cls == kSkipped) {
        fcomp[f] = kNone;
        fpar[f] = 0;
        continue;
      }
      std::uint8_t par;
      const std::uint32_t r = uf_find(F, f, par);
      if (cidx[r] == kNone) {
        cidx[r] = static_cast<std::uint32_t>(ncomp_++);
        ws_.comp_lo.push_back(V3{inf, inf, inf});
        ws_.comp_hi.push_back(V3{-inf, -inf, -inf});
      }
      fcomp[f] = cidx[r];
      fpar[f] = par;
    }
    stats_->components = ncomp_;
    // Signed volume of each part about its low point org (bounding-box centre in x, y; lowest z):
    // a planar face's cone from org is (1/6) net . (c - org), net being twice its area vector (its
    // Newell normal less its holes') and c any point of it. Summed per part with the faces' parities:
    // (1/6) (sum net.c - (sum net) . org), so one pass over the faces and none over the edges.
    ws_.comp_vol.assign(ncomp_, 0);
    ws_.comp_area.assign(ncomp_, 0);
    ws_.comp_net.assign(ncomp_, V3{});
    V3* CLO = ws_.comp_lo.data();
    V3* CHI = ws_.comp_hi.data();
    double* CVOL = ws_.comp_vol.data();
    double* CAREA = ws_.comp_area.data();
    V3* CNET = ws_.comp_net.data();
    for (std::uint32_t f = 0; f < nf; ++f) {
      if (F[f].cls == kSkipped) continue;
      const FaceInfo& fi = F[f];
      const std::uint32_t c = fcomp[f];
      V3& lo = CLO[c];
      V3& hi = CHI[c];
      lo.x = std::min(lo.x, fi.lo.x), lo.y = std::min(lo.y, fi.lo.y), lo.z = std::min(lo.z, fi.lo.z);
      hi.x = std::max(hi.x, fi.hi.x), hi.y = std::max(hi.y, fi.hi.y), hi.z = std::max(hi.z, fi.hi.z);
      CAREA[c] += fi.len / 2;
      const double s = fpar[f] ? -1.0 : 1.0;
      CVOL[c] += s * dot(fi.net, fi.c);
      V3& N = CNET[c];
      N.x += s * fi.net.x, N.y += s * fi.net.y, N.z += s * fi.net.z;
    }
    for (std::size_t c = 0; c < ncomp_; ++c) {
      const V3 org{(CLO[c].x + CHI[c].x) / 2, (CLO[c].y + CHI[c].y) / 2, CLO[c].z};
      CVOL[c] = (CVOL[c] - dot(CNET[c], org)) / 6;
    }
    ws_.comp_sign.assign(ncomp_, 0);
    std::int8_t* CS = ws_.comp_sign.data();
    for (std::size_t c = 0; c < ncomp_; ++c) {
      const double scale = std::pow(std::max(CAREA[c], 1e-12), 1.5);
      const double v = CVOL[c];
      if (std::fabs(v) > 1e-6 * scale) CS[c] = v > 0 ? 1 : -1;
      else ++stats_->unoriented_components;
    }
    std::size_t flipped = 0;
    for (std::uint32_t f = 0; f < nf; ++f) {
      if (F[f].cls == kSkipped) continue;
      const std::int8_t cs = CS[fcomp[f]] == 0 ? 1 : CS[fcomp[f]];
      F[f].sign = static_cast<std::int8_t>(fpar[f] ? -cs : cs);
      flipped += F[f].sign < 0;
    }
    stats_->flipped_faces += flipped;
  }

  // ---- 4. decomposition -------------------------------------------------------------------------
  void classify() {
    // Walls were told at build time; the rest face up (ceiling) or down (floor) once oriented.
    for (FaceInfo& fi : ws_.faces)
      if (fi.cls == kFloor || fi.cls == kCeiling) fi.cls = fi.sign * fi.n.z > 0 ? kCeiling : kFloor;
  }

  std::uint32_t comp_of(std::uint32_t f) const { return ws_.face_comp[f]; }

  /// Floor patches from whose boundary a wall goes down are soffits (the underside of an upper
  /// storey wider than the one below), not ground: walls rising from them are no footprint, or a
  /// storey overhanging on every side would give its shadow. hanging[f] for floor facets.
  void find_hanging_floors() {
    const std::size_t nf = ws_.faces.size();
    auto& par = ws_.floor_uf;
    par.resize(nf);
    ws_.hanging.assign(nf, 0);
    bool any = false;
    for (std::uint32_t f = 0; f < nf; ++f) {
      par[f] = f;
      any |= ws_.faces[f].cls == kFloor;
    }
    if (!any) return;
    auto find = [&](std::uint32_t x) {
      while (par[x] != x) x = par[x] = par[par[x]];
      return x;
    };
    const std::size_t ng = ws_.group_count.size();
    for (int pass = 0; pass < 2; ++pass)
      for (std::size_t g = 0; g < ng; ++g) {
        const std::uint32_t s = ws_.group_start[g], c = ws_.group_count[g];
        std::uint32_t first_floor = kNone;
        bool down = false;
        for (std::uint32_t i = 0; i < c; ++i) {
          const HalfEdge& h = ws_.halfedges[ws_.group_members[s + i]];
          const std::uint8_t cls = ws_.faces[h.face].cls;
          if (cls == kWall && h.up < 0) down = true;
          if (cls != kFloor) continue;
          if (pass == 0) {
            if (first_floor == kNone) first_floor = h.face;
            else par[find(h.face)] = find(first_floor);
          }
        }
        if (pass == 1 && down)
          for (std::uint32_t i = 0; i < c; ++i) {
            const HalfEdge& h = ws_.halfedges[ws_.group_members[s + i]];
            if (ws_.faces[h.face].cls == kFloor) ws_.hanging[find(h.face)] = 1;
          }
      }
    for (std::uint32_t f = 0; f < nf; ++f)
      if (ws_.faces[f].cls == kFloor) ws_.hanging[f] = ws_.hanging[find(f)];
  }

  void fill_decomposition(SurfaceDecomposition& dec) {
    // Patches: facets of one class connected through shared edges. With the proxy normal fixed to
    // the vertical, the VSA growth from the lowest seeds reaches exactly these sets.
    const std::size_t nf = ws_.faces.size();
    std::vector<std::uint32_t> parent(nf);
    for (std::uint32_t f = 0; f < nf; ++f) parent[f] = f;
    auto find = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    const std::size_t ng = ws_.group_count.size();
    for (std::size_t g = 0; g < ng; ++g) {
      const std::uint32_t s = ws_.group_start[g], c = ws_.group_count[g];
      for (std::uint32_t i = 0; i < c; ++i)
        for (std::uint32_t j = i + 1; j < c; ++j) {
          const std::uint32_t f1 = ws_.halfedges[ws_.group_members[s + i]].face;
          const std::uint32_t f2 = ws_.halfedges[ws_.group_members[s + j]].face;
          if (ws_.faces[f1].cls != ws_.faces[f2].cls) continue;
          const std::uint32_t r1 = find(f1), r2 = find(f2);
          if (r1 != r2) parent[std::max(r1, r2)] = std::min(r1, r2);
        }
    }
    dec = SurfaceDecomposition{};
    dec.face_patch.assign(nf, -1);
    std::vector<std::int32_t> root_patch(nf, -1);
    // Bottom-up numbering: patches in order of their lowest facet.
    std::vector<std::pair<double, std::uint32_t>> order;
    for (std::uint32_t f = 0; f < nf; ++f) {
      if (ws_.faces[f].cls == kSkipped) continue;
      double zmin = std::numeric_limits<double>::infinity();
      const MeshFace& mf = m_.faces[f];
      for (std::uint32_t k = m_.ring_offsets[mf.first_ring]; k < m_.ring_offsets[mf.first_ring + 1]; ++k)
        zmin = std::min(zmin, m_.vertices[m_.indices[k]].z);
      order.emplace_back(zmin, f);
    }
    std::stable_sort(order.begin(), order.end());
    for (auto [z, f] : order) {
      const std::uint32_t r = find(f);
      if (root_patch[r] < 0) {
        root_patch[r] = static_cast<std::int32_t>(dec.patch_kind.size());
        const std::uint8_t cls = ws_.faces[f].cls;
        dec.patch_kind.push_back(cls == kFloor ? PatchKind::Floor : cls == kCeiling ? PatchKind::Ceiling : PatchKind::Wall);
        dec.patch_z.push_back(0);
        dec.patch_area_m2.push_back(0);
      }
      const std::int32_t pid = root_patch[r];
      dec.face_patch[f] = pid;
      // Area-weighted mean z of the facet's outer ring vertices (the proxy plane's height).
      const MeshFace& mf = m_.faces[f];
      double zs = 0;
      const std::uint32_t a = m_.ring_offsets[mf.first_ring], b = m_.ring_offsets[mf.first_ring + 1];
      for (std::uint32_t k = a; k < b; ++k) zs += m_.vertices[m_.indices[k]].z;
      const double area = ws_.faces[f].len / 2;
      dec.patch_z[pid] += area * zs / (b - a);
      dec.patch_area_m2[pid] += area;
    }
    for (std::size_t p = 0; p < dec.patch_z.size(); ++p)
      dec.patch_z[p] = dec.patch_area_m2[p] > 0 ? dec.patch_z[p] / dec.patch_area_m2[p] : 0;
  }

  // ---- 5. lower boundary of the walls -----------------------------------------------------------
  void collect_footprint_edges() {
    auto& cand = ws_.cand;
    cand.clear();
    const std::size_t ng = ws_.group_count.size();
    const std::uint32_t* cnt = ws_.group_count.data();
    const std::uint32_t* st = ws_.group_start.data();
    const std::uint32_t* mem = ws_.group_members.data();
    const HalfEdge* H = ws_.halfedges.data();
    const FaceInfo* F = ws_.faces.data();
    const std::uint8_t* hanging = ws_.hanging.data();
    for (std::size_t g = 0; g < ng; ++g) {
      const std::uint32_t s = st[g], c = cnt[g];
      int net = 0;
      bool below = false;
      std::uint32_t comp = kNone, lo = 0, hi = 0;
      for (std::uint32_t i = 0; i < c; ++i) {
        const HalfEdge& h = H[mem[s + i]];
        const FaceInfo& fi = F[h.face];
        if (fi.cls == kCeiling || (fi.cls == kFloor && hanging[h.face])) {
          // A ceiling boundary (paper §4: "except the ceiling boundaries"): walls rising from a roof
          // (the inside of a parapet, a penthouse) stand on the building, not on the ground; so do
          // walls rising from a soffit.
          below = true;
          break;
        }
        if (fi.cls != kWall) continue;
        if (h.up < 0) {
          below = true;
          break;
        }
        if (h.up == 0) continue;
        // Outward orientation: the building lies left of the edge seen from above.
        const std::uint32_t from = fi.sign > 0 ? h.a : h.b;
        lo = std::min(h.a, h.b);
        hi = std::max(h.a, h.b);
        net += from == lo ? 1 : -1;
        if (comp == kNone) comp = comp_of(h.face);
      }
      if (below || net == 0) continue;
      for (int k = 0; k < std::abs(net); ++k) cand.push_back(net > 0 ? DirEdge{lo, hi, comp} : DirEdge{hi, lo, comp});
    }
    stats_->footprint_edges = cand.size();
  }

  // ---- 6. loops ---------------------------------------------------------------------------------
  void chain_loops() {
    chain_pass(true);
    if (stats_->open_chains == 0) return;
    auto& cand = ws_.cand;
    lower_boundary_len_ = 0;
    for (const DirEdge& e : cand) lower_boundary_len_ += plan_length(e);
    // Rule 2: the edges left open are chained again in plan view. A bottom that steps at a vertical
    // wall edge (terraced sites, a wall on a plinth on one side only) is broken in 3D but continuous
    // in plan, and the footprint is a plan-view object. Loops already closed stay as they are.
    auto& open = ws_.open_tmp;
    open.clear();
    for (std::uint32_t e : ws_.open_edges) open.push_back(cand[e]);
    if (!merge_in_plan(open)) return;
    const std::size_t loops_before = ws_.loops.size();
    cand.swap(open);
    stats_->open_chains = 0;
    chain_pass(false);
    stats_->chained_in_plan = ws_.loops.size() - loops_before;
  }

  double plan_length(const DirEdge& e) const {
    const V3 &a = ws_.wpos[e.from], &b = ws_.wpos[e.to];
    return std::hypot(b.x - a.x, b.y - a.y);
  }

  /// Footprint-edge endpoints within the weld tolerance in x, y become one vertex (the one of
  /// smallest id); edges that collapse go. False when nothing was merged.
  bool merge_in_plan(std::vector<DirEdge>& cand) {
    auto& ends = ws_.endpoints;
    ends.clear();
    for (const DirEdge& e : cand) ends.push_back(e.from), ends.push_back(e.to);
    const auto& P = ws_.wpos;
    std::sort(ends.begin(), ends.end(), [&](std::uint32_t u, std::uint32_t v) { return P[u].x < P[v].x || (P[u].x == P[v].x && u < v); });
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    auto& rep = ws_.plan_rep;
    rep.resize(P.size());
    for (std::uint32_t v : ends) rep[v] = v;
    auto find = [&](std::uint32_t x) {
      while (rep[x] != x) x = rep[x] = rep[rep[x]];
      return x;
    };
    bool any = false;
    for (std::size_t i = 0; i < ends.size(); ++i)
      for (std::size_t j = i + 1; j < ends.size() && P[ends[j]].x - P[ends[i]].x <= tol_; ++j) {
        if (std::fabs(P[ends[j]].y - P[ends[i]].y) > tol_) continue;
        const std::uint32_t a = find(ends[i]), b = find(ends[j]);
        if (a == b) continue;
        rep[std::max(a, b)] = std::min(a, b);
        any = true;
      }
    if (!any) return false;
    std::size_t k = 0;
    for (const DirEdge& e : cand) {
      const DirEdge m{find(e.from), find(e.to), e.comp};
      if (m.from != m.to) cand[k++] = m;
    }
    cand.resize(k);
    return true;
  }

  /// Chains ws_.cand into loops (appended to ws_.loops; cleared first when `fresh`); the edges of
  /// chains that do not close go to ws_.open_edges.
  void chain_pass(bool fresh) {
    auto& cand = ws_.cand;
    if (fresh) {
      ws_.loops.clear();
      ws_.loop_pts.clear();
    }
    ws_.open_edges.clear();
    if (cand.empty()) return;
    const std::size_t nv = ws_.wpos.size(), ne = cand.size();
    ws_.out_start.assign(nv + 1, 0);
    for (const DirEdge& e : cand) ++ws_.out_start[e.from + 1];
    for (std::size_t v = 0; v < nv; ++v) ws_.out_start[v + 1] += ws_.out_start[v];
    ws_.out_list.resize(ne);
    {
      auto& cursor = ws_.stamp;  // borrowed as a cursor
      cursor.assign(ws_.out_start.begin(), ws_.out_start.end() - 1);
      for (std::uint32_t i = 0; i < ne; ++i) ws_.out_list[cursor[cand[i].from]++] = i;
    }
    ws_.used.assign(ne, 0);
    ws_.stamp.assign(nv, 0);  // position in the current chain + 1, 0 = not in it
    auto& cv = ws_.chain_v;
    auto& ce = ws_.chain_e;
    for (std::uint32_t e0 = 0; e0 < ne; ++e0) {
      if (ws_.used[e0]) continue;
      cv.clear();
      ce.clear();
      cv.push_back(cand[e0].from);
      ws_.stamp[cand[e0].from] = 1;
      std::uint32_t e = e0;
      for (;;) {
        ws_.used[e] = 1;
        ce.push_back(e);
        const std::uint32_t v = cand[e].to;
        if (ws_.stamp[v] != 0) {
          // Back at a vertex of this chain: the part from there is a closed loop.
          const std::size_t k = ws_.stamp[v] - 1;
          emit_loop(k);
          for (std::size_t j = k + 1; j < cv.size(); ++j) ws_.stamp[cv[j]] = 0;
          cv.resize(k + 1);
          ce.resize(k);
        } else {
          cv.push_back(v);
          ws_.stamp[v] = static_cast<std::uint32_t>(cv.size());
        }
        const std::uint32_t next = pick_next(cv.back(), ce.empty() ? kNone : ce.back());
        if (next == kNone) break;
        e = next;
      }
      if (!ce.empty()) {
        ++stats_->open_chains;
        ws_.open_edges.insert(ws_.open_edges.end(), ce.begin(), ce.end());
      }
      for (std::uint32_t v : cv) ws_.stamp[v] = 0;
    }
  }

  /// The unused edge out of v making the leftmost turn after edge `in` (any unused one if none).
  std::uint32_t pick_next(std::uint32_t v, std::uint32_t in) {
    std::uint32_t best = kNone;
    double best_ang = 10;
    const std::uint32_t s = ws_.out_start[v], t = ws_.out_start[v + 1];
    std::uint32_t avail = 0;
    for (std::uint32_t i = s; i < t; ++i) avail += !ws_.used[ws_.out_list[i]];
    if (avail == 0) return kNone;
    double back = 0;
    if (in != kNone && avail > 1) {
      const V3 d = ws_.wpos[ws_.cand[in].from] - ws_.wpos[v];
      back = std::atan2(d.y, d.x);
    }
    for (std::uint32_t i = s; i < t; ++i) {
      const std::uint32_t e = ws_.out_list[i];
      if (ws_.used[e]) continue;
      if (avail == 1 || in == kNone) return e;
      const V3 d = ws_.wpos[ws_.cand[e].to] - ws_.wpos[v];
      // Clockwise angle from the way back to this way, in (0, 2 pi]: the smallest is the leftmost turn.
      double a = back - std::atan2(d.y, d.x);
      while (a <= 1e-12) a += 2 * kPi;
      while (a > 2 * kPi) a -= 2 * kPi;
      if (a < best_ang) {
        best_ang = a;
        best = e;
      }
    }
    return best;
  }

  /// Loop = chain vertices from position k to the end (the last edge returns to cv[k]).
  void emit_loop(std::size_t k) {
    const auto& cv = ws_.chain_v;
    Workspace::Loop L;
    L.comp = ws_.cand[ws_.chain_e[k]].comp;
    L.first = ws_.loop_pts.size();
    L.zmax = -std::numeric_limits<double>::infinity();
    for (std::size_t j = k; j < cv.size(); ++j) {
      const V3& p = ws_.wpos[cv[j]];
      L.zmax = std::max(L.zmax, p.z);
      const Point2 q{p.x, p.y};
      if (ws_.loop_pts.size() > L.first) {
        const Point2& b = ws_.loop_pts.back();
        if (b.x == q.x && b.y == q.y) continue;
      }
      ws_.loop_pts.push_back(q);
    }
    while (ws_.loop_pts.size() - L.first > 1 && ws_.loop_pts.back() == ws_.loop_pts[L.first]) ws_.loop_pts.pop_back();
    L.count = ws_.loop_pts.size() - L.first;
    double a = 0;
    L.minx = L.miny = std::numeric_limits<double>::infinity();
    L.maxx = L.maxy = -L.minx;
    const Point2* r = ws_.loop_pts.data() + L.first;
    for (std::size_t i = 0; i < L.count; ++i) {
      const Point2 &p = r[i], &q = r[i + 1 < L.count ? i + 1 : 0];
      a += p.x * q.y - q.x * p.y;
      L.minx = std::min(L.minx, p.x), L.maxx = std::max(L.maxx, p.x);
      L.miny = std::min(L.miny, p.y), L.maxy = std::max(L.maxy, p.y);
    }
    L.area = a / 2;
    ++stats_->loops;
    if (L.count < 3 || !(std::fabs(L.area) >= p_.min_loop_area_m2)) {
      ++stats_->dropped_loops;
      ws_.loop_pts.resize(L.first);
      return;
    }
    ws_.loops.push_back(L);
  }

  // ---- 7. polygons ------------------------------------------------------------------------------
  bool loop_contains(const Workspace::Loop& outer, const Workspace::Loop& h) const {
    if (h.minx < outer.minx || h.maxx > outer.maxx || h.miny < outer.miny || h.maxy > outer.maxy) return false;
    // Probe: midpoint of the hole's longest edge (its vertices may touch the outer ring).
    const Point2* r = ws_.loop_pts.data() + h.first;
    std::size_t best = 0;
    double bl = -1;
    for (std::size_t i = 0; i < h.count; ++i) {
      const Point2 &p = r[i], &q = r[i + 1 < h.count ? i + 1 : 0];
      const double l = (q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y);
      if (l > bl) bl = l, best = i;
    }
    const Point2 &p = r[best], &q = r[best + 1 < h.count ? best + 1 : 0];
    return inside(ws_.loop_pts.data() + outer.first, outer.count, Point2{(p.x + q.x) / 2, (p.y + q.y) / 2});
  }

  void make_polygons(std::vector<Polygon>& out) {
    auto& loops = ws_.loops;
    // Parts whose outside is unknown: outer or hole by nesting depth among that part's loops.
    if (stats_->unoriented_components > 0) {
      for (std::size_t i = 0; i < loops.size(); ++i) {
        if (ws_.comp_sign[loops[i].comp] != 0) continue;
        std::size_t depth = 0;
        Workspace::Loop li = loops[i];
        if (li.area < 0) li.area = -li.area;
        for (std::size_t j = 0; j < loops.size(); ++j)
          if (j != i && loops[j].comp == loops[i].comp && std::fabs(loops[j].area) > li.area && loop_contains(loops[j], loops[i]))
            ++depth;
        const bool want_ccw = depth % 2 == 0;
        if ((loops[i].area > 0) != want_ccw) {
          std::reverse(ws_.loop_pts.begin() + loops[i].first, ws_.loop_pts.begin() + loops[i].first + loops[i].count);
          loops[i].area = -loops[i].area;
        }
      }
    }
    auto& poly_of_loop = ws_.poly_of_loop;
    poly_of_loop.assign(loops.size(), -1);
    auto ring = [&](const Workspace::Loop& L) {
      Ring r(L.count);
      const Point2* s = ws_.loop_pts.data() + L.first;
      for (std::size_t i = 0; i < L.count; ++i) r[i] = Point2{s[i].x + o_.x, s[i].y + o_.y};
      return r;
    };
    for (std::size_t i = 0; i < loops.size(); ++i) {
      if (loops[i].area <= 0) continue;
      poly_of_loop[i] = static_cast<std::int32_t>(out.size());
      out.push_back(Polygon{ring(loops[i]), {}});
    }
    for (std::size_t i = 0; i < loops.size(); ++i) {
      if (loops[i].area > 0) continue;
      const Workspace::Loop& h = loops[i];
      // The smallest outer ring containing the hole, one of its own part if any does.
      std::int32_t best = -1;
      double best_area = std::numeric_limits<double>::infinity();
      bool best_same = false;
      for (std::size_t j = 0; j < loops.size(); ++j) {
        if (poly_of_loop[j] < 0 || loops[j].area <= -h.area) continue;
        const bool same = loops[j].comp == h.comp;
        const bool better = best < 0 || (same && !best_same) || (same == best_same && loops[j].area < best_area);
        if (!better || !loop_contains(loops[j], h)) continue;
        best = poly_of_loop[j];
        best_area = loops[j].area;
        best_same = same;
      }
      if (best < 0) {
        ++stats_->dropped_loops;
        continue;
      }
      out[best].holes.push_back(ring(h));
      ++stats_->holes;
    }
  }

  /// True when a tenth or more of the lower boundary (by plan length) lies in open chains outside
  /// every outer loop and no higher than the loops reach: then the loops miss part of where the
  /// building stands. Open chains inside a loop (a part standing on another) or above every loop
  /// (a balcony, a canopy: floating slabs are local minima too, but not ground) do not count.
  bool open_outside_loops() const {
    if (ws_.open_edges.empty()) return false;
    double zmax = -std::numeric_limits<double>::infinity();
    for (const Workspace::Loop& L : ws_.loops) zmax = std::max(zmax, L.zmax);
    double outside = 0;
    for (std::uint32_t e : ws_.open_edges) {
      const V3 &a = ws_.wpos[ws_.cand[e].from], &b = ws_.wpos[ws_.cand[e].to];
      if (std::min(a.z, b.z) > zmax + tol_) continue;
      const Point2 mid{(a.x + b.x) / 2, (a.y + b.y) / 2};
      bool in = false;
      for (const Workspace::Loop& L : ws_.loops) {
        if (L.area <= 0 || mid.x < L.minx || mid.x > L.maxx || mid.y < L.miny || mid.y > L.maxy) continue;
        if ((in = inside(ws_.loop_pts.data() + L.first, L.count, mid))) break;
      }
      if (!in) outside += plan_length(ws_.cand[e]);
    }
    return outside >= 0.1 * lower_boundary_len_;
  }

  // ---- 8. the shadow: last resort --------------------------------------------------------------
  /// Rule 3: the loops miss where the building stands (a mesh full of gaps, walls
  /// on roofs they share no edge with, faces that end short of each other: SketchUp exports). The
  /// shadow, the union of every used facet's vertical projection, is what is certain about where
  /// the building stands: it is the footprint wherever the building does not overhang its base.
  /// The union is the project's exact engine on one footprint; should it fail, the projected facets
  /// go out as they are (overlapping polygons, which the pipeline's union merges anyway).
  void make_shadow(std::vector<Polygon>& out) {
    Footprint fp;
    double minx = std::numeric_limits<double>::infinity(), maxx = -minx, miny = minx, maxy = -minx;
    for (std::uint32_t f = 0; f < ws_.faces.size(); ++f) {
      // Walls too: one leaning by a hair bridges a modelling gap of millimetres (an annex drawn a
      // hair off the hall); the slivers they leave elsewhere are dropped below.
      if (ws_.faces[f].cls == kSkipped) continue;
      const MeshFace& mf = m_.faces[f];
      Polygon poly;
      for (std::uint32_t r = mf.first_ring; r < mf.first_ring + mf.ring_count; ++r) {
        if (!welded_ring(r) || ws_.ring_tmp.size() < 3) continue;
        Ring ring;
        ring.reserve(ws_.ring_tmp.size());
        double a = 0;
        for (std::size_t i = 0; i < ws_.ring_tmp.size(); ++i) {
          const V3& p = ws_.wpos[ws_.ring_tmp[i]];
          const V3& q = ws_.wpos[ws_.ring_tmp[i + 1 < ws_.ring_tmp.size() ? i + 1 : 0]];
          a += p.x * q.y - q.x * p.y;
          ring.push_back(Point2{p.x + o_.x, p.y + o_.y});
        }
        if (!(std::fabs(a / 2) >= p_.min_loop_area_m2)) {
          if (r == mf.first_ring) break;  // seen edge-on: no area, its holes neither
          continue;
        }
        const bool outer = r == mf.first_ring;
        if ((a > 0) != outer) std::reverse(ring.begin(), ring.end());
        if (outer) {
          for (const Point2& q : ring)
            minx = std::min(minx, q.x), maxx = std::max(maxx, q.x), miny = std::min(miny, q.y), maxy = std::max(maxy, q.y);
          poly.outer = std::move(ring);
        } else {
          poly.holes.push_back(std::move(ring));
        }
      }
      if (!poly.outer.empty()) fp.polygons.push_back(std::move(poly));
    }
    if (fp.polygons.empty()) return;
    stats_->shadow = true;
    UnionParams up;
    up.threads = 1;  // decomposition runs on the caller's thread (the pipeline parallelises buildings)
    up.device = Device::Cpu;
    up.resolution_m = std::max({maxx - minx, maxy - miny, 1e-6}) / 256;  // blocks only; exactness does not depend on it
    std::vector<Problem> problems;
    std::vector<GroundPlan> plans;
    try {
      plans = build_ground_plans(std::vector<Footprint>{fp}, up, problems);
    } catch (const std::exception&) {
      plans.clear();
    }
    if (plans.empty()) {
      out = std::move(fp.polygons);
      return;
    }
    // Rings under kShadowMinRing_m2 are what walls leaning by a hair leave along their lines.
    for (GroundPlan& g : plans) {
      if (std::fabs(ring_area(g.polygon.outer)) < kShadowMinRing_m2) continue;
      auto& h = g.polygon.holes;
      h.erase(std::remove_if(h.begin(), h.end(), [](const Ring& r) { return std::fabs(ring_area(r)) < kShadowMinRing_m2; }), h.end());
      out.push_back(std::move(g.polygon));
    }
  }
};

}  // namespace

DecomposeResult decompose_footprint(const Mesh& mesh, const DecomposeParams& params, SurfaceDecomposition* decomposition) {
  Decomposer d(mesh, params, workspace());
  return d.run(decomposition);
}

}  // namespace groundplan::footprint
