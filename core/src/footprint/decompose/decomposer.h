// SPDX-License-Identifier: MIT
#pragma once
// Internal to the decomposition (core/src/footprint/decompose.cpp and decompose/*.cpp): the per-thread
// scratch buffers and the Decomposer, one object per mesh whose stages are methods, each stage defined
// in its own file of this folder:
//   weld.cpp            1. vertices within weld_tolerance_m become one
//   topology.cpp        2. faces, duplicate faces, half-edges grouped by undirected edge
//   t_junctions.cpp     2b. open edges split where another open edge ends on them
//   orientation.cpp     3. every part's facets turned outward
//   classification.cpp  4. floor / ceiling / wall patches, hanging floors (soffits)
//   lower_boundary.cpp  5. footprint edges: lower boundary of the walls, local minima
//   loops.cpp           6. footprint edges chained into loops (3D, then in plan view)
//   polygons.cpp        7. loops to polygons with holes
//   unite.cpp           7b. one footprint's polygons united
//   plan_faces.cpp      7c. when the loops miss: the lower boundary closed in plan
//   shadow.cpp          8. the shadow, when the loops miss where the building stands
// The per-vertex helpers of the weld, called from the ring pass in topology.cpp, stay inline here.
#include "footprint/decompose.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace groundplan::footprint::detail {

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint32_t kBad = kNone - 1;  // a vertex with NaN or infinite coordinates
/// A wall facet "rises" from an edge when the in-plane direction into it has at least this z
/// component (unit vectors): vertical edges (0) and edges of walls leaning < 0.6° are neither.
constexpr double kRise = 0.01;
/// A floor patch from whose edges walls go down is a soffit (it hangs) when its mean depth beyond those
/// edges (plan area / their plan length) is at most this many times the walls' drop below it; deeper,
/// it is a step of the ground (a building on a slope, its floor following the terrain). A cantilever
/// reaches out about as far as it stands high (stepped_ground in tests/support/known_footprints.cpp:
/// 10 m deep over a 2 m riser; cantilever: 2 m over 3 m; boxed eaves: 0.9 m over 3 m).
constexpr double kStepDepthPerDrop = 2;
/// Stage 7c (plan_faces.cpp): lower-boundary ends this close in plan are one point when the loops
/// failed (SketchUp parts ending 7 to 8 cm apart: Macky). Metres.
constexpr double kPlanGap_m = 0.1;

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
  std::vector<DirEdge> lower_edges;  // every lower-boundary edge while cand holds merged open ones
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
  /// Floor facets of a patch from whose edge a wall goes down but too little for its depth to be a
  /// soffit: a step of the ground under a building on a slope (classification.cpp); the wall going
  /// down is the riser, and the patch's edge on it bounds the footprint (lower_boundary.cpp).
  std::vector<std::uint8_t> step_floor;
  std::vector<double> patch_plan_area, patch_down_len, patch_drop;  // per floor patch root, while hanging
  // contacts.cpp: a face's outer ring projected along its normal, made when an edge first reaches
  // the point-in-face test (face_pts_at[f] kNone until then; face_pts_n[f] points from there)
  std::vector<std::uint32_t> face_pts_at, face_pts_n;
  std::vector<Point2> face_pts;
  std::vector<std::uint8_t> on_roof;  // per edge group: its walls stand on another part's ceiling (contacts.cpp)
  /// contacts.cpp: the used faces bucketed by their plan boxes in an n x n grid (CSR), so that an edge
  /// is tried against the faces near it, not all of them; floors and ceilings (rules a, b) apart from
  /// walls (rule c), which are most faces and asked for least.
  struct FaceGrid {
    int n = 1;
    double x0 = 0, y0 = 0, sx = 1, sy = 1;  // cell of x: (x - x0) * sx, clamped
    std::vector<std::uint32_t> start[2], faces[2];  // [0] floors and ceilings, [1] walls
    std::vector<std::uint32_t> stamp, near;
    std::uint32_t gen = 0;
  } grid;
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

/// The calling thread's scratch buffers (decompose.cpp).
Workspace& workspace();

inline std::uint32_t uf_find(FaceInfo* f, std::uint32_t i, std::uint8_t& parity) {
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

inline double ring_area(const Ring& r) {
  double a = 0;
  for (std::size_t i = 0, j = r.size() - 1; i < r.size(); j = i++) a += (r[j].x - r[i].x) * (r[j].y + r[i].y);
  return a / 2;
}

/// Point in ring (crossing number), ring relative coordinates.
inline bool inside(const Point2* ring, std::size_t n, Point2 p) {
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

/// `polys` replaced by their union (the project's exact engine), rings under min_ring_m2 dropped;
/// false (and `polys` unchanged) when the engine fails. unite.cpp.
bool unite_polygons(std::vector<Polygon>& polys, double min_ring_m2);

class Decomposer {
 public:
  Decomposer(const Mesh& m, const DecomposeParams& p, Workspace& ws) : m_(m), p_(p), ws_(ws) {}

  DecomposeResult run(SurfaceDecomposition* dec);

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
  bool lower_moved_ = false;  // chain_loops() moved every lower-boundary edge to ws_.lower_edges

  bool find_origin();

  // ---- 1. welding (weld.cpp) ------------------------------------------------------------------------
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
  bool distinct_apart();

  /// The grid weld (vertices within tol of each other): exact copies through one hash of the raw
  /// coordinates, points not seen before through the tolerance grid (weld_new). Grid cells are
  /// kCell x tol wide, so a point needs the neighbouring cell on an axis only within tol of that
  /// side (mostly one probe).
  std::uint32_t weld_vertex_grid(std::uint32_t vi);

  /// Welded id of a point not seen before (by its exact coordinates).
  std::uint32_t weld_new(const Point3& q);

  /// Welded vertices of ring r into ring_tmp, consecutive repeats (and the closing repeat) removed.
  /// False when the ring has an index out of range or a non-finite vertex.
  bool welded_ring(std::uint32_t r);

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

  // ---- 2. faces and half-edges (topology.cpp) -------------------------------------------------------
  /// Remembers the face's welded outer ring (ring_buf); a face seen before with the same ring (any
  /// start, either direction) and ring count is noted in `dups` for resolve_duplicates(), with
  /// `fwd` telling whether it runs the way the first one does. The hash does not depend on start
  /// or direction, so nothing is rotated unless two hashes meet.
  void note_face(std::uint32_t f, std::uint32_t ring_count);

  /// +1 when ring b is ring a from another start, -1 when it is a reversed, 0 otherwise (k >= 3).
  static int same_cycle(const std::uint32_t* a, const std::uint32_t* b, std::size_t k);

  /// Faces written more than once. Copies running opposite ways are a face between two solids of one
  /// mesh (each part closed on its own): both go, and the parts merge into one solid. Copies running
  /// the same way are one face written twice (exporters do it): one stays. Either would otherwise
  /// make the edges non-manifold and cancel the part's volume.
  void resolve_duplicates();

  void build_faces();

  /// One pass per ring (outer, then holes) that welds, takes the Newell normal and bounding box
  /// (repeated vertices add exact zeros to the normal), notes the face for duplicates, and makes the
  /// boundary-oriented half-edges and groups them by undirected welded edge as they come (groups
  /// numbered in order of first appearance; the earlier half-edges with the same smaller vertex are
  /// chained per vertex, a handful). Without the grid a vertex is its distinct point, numbered in
  /// order of first use. The groups are final unless a face is dropped as a duplicate (then run()
  /// groups again, group_edges()).
  template <bool Grid>
  void build_face_rings();

  /// Groups from he_group and cnt_buf (ng groups): group_count, group_start, group_members.
  void finish_groups(std::uint32_t ng);

  /// group_start and group_members (counting sort of the half-edges by he_group) from group_count.
  void sort_group_members(std::uint32_t ng);


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
  void group_edges();

  // ---- T-junctions (t_junctions.cpp) ----------------------------------------------------------------
  /// Splits every edge seen by one facet at the ends of other such edges lying on it (within tol).
  /// Returns whether anything was split (then the edges must be regrouped).
  bool split_t_junctions();

  /// Whether some end of an edge seen by one facet lies on another such edge by the split's test
  /// (x within the edge's x range widened by tol, then 0 < t < 1 and squared offset within tol^2):
  /// exactly when the split would split something. Fewer than two such edges: never. The ends (each
  /// vertex once) are tried against every edge when there are few (a closed part without its ground
  /// has its bottom ring), else in x order from a binary search.
  bool open_end_on_open_edge();

  // ---- 3. orientation (orientation.cpp) -------------------------------------------------------------
  void orient();

  // ---- 4. decomposition (classification.cpp) --------------------------------------------------------
  void classify();

  std::uint32_t comp_of(std::uint32_t f) const { return ws_.face_comp[f]; }

  /// Floor patches from whose boundary a wall goes down are soffits (the underside of an upper
  /// storey wider than the one below), not ground: walls rising from them are no footprint, or a
  /// storey overhanging on every side would give its shadow. hanging[f] for floor facets.
  void find_hanging_floors();

  // ---- 4b. contacts: parts that touch without sharing edges (contacts.cpp) -----------------------
  /// Floors hang, and wall bottoms stand on roofs, where an edge of one part lies in a face of
  /// another (issue 21): ws_.hanging, ws_.on_roof.
  void find_contacts();
  /// Face f's outer ring projected along its normal's largest component, made on first use (most
  /// faces are never tested: every face cost as much as the rest of the contacts on Macky).
  const Point2* projected_face(std::uint32_t f, std::size_t& n);
  /// ws_.grid over the used faces' plan boxes.
  void index_faces();
  /// The used faces (floors and ceilings, and walls when `walls`) whose plan box meets the edge p q's
  /// widened by tol: ws_.grid.near, in increasing order when `walls`.
  void faces_near(const V3& p, const V3& q, bool walls);
  /// Whether the edge p q lies in face f within the weld tolerance (ends on its plane, midpoint on it).
  bool edge_on_face(std::uint32_t f, const V3& p, const V3& q);

  // ---- 7b. one footprint never overlaps itself (unite.cpp) ---------------------------------------
  /// Polygons whose boxes meet are united with the project's union engine (issue 21).
  void unite_loops(std::vector<Polygon>& polys);

  void fill_decomposition(SurfaceDecomposition& dec);

  // ---- 5. lower boundary of the walls (lower_boundary.cpp) ------------------------------------------
  void collect_footprint_edges();

  // ---- 6. loops (loops.cpp) -------------------------------------------------------------------------
  void chain_loops();

  double plan_length(const DirEdge& e) const {
    const V3 &a = ws_.wpos[e.from], &b = ws_.wpos[e.to];
    return std::hypot(b.x - a.x, b.y - a.y);
  }

  /// Footprint-edge endpoints within the weld tolerance in x, y become one vertex (the one of
  /// smallest id); edges that collapse go. False when nothing was merged.
  bool merge_in_plan(std::vector<DirEdge>& cand);

  /// Chains ws_.cand into loops (appended to ws_.loops; cleared first when `fresh`); the edges of
  /// chains that do not close go to ws_.open_edges.
  void chain_pass(bool fresh);

  /// The unused edge out of v making the leftmost turn after edge `in` (any unused one if none).
  std::uint32_t pick_next(std::uint32_t v, std::uint32_t in);

  /// Loop = chain vertices from position k to the end (the last edge returns to cv[k]).
  void emit_loop(std::size_t k);

  // ---- 7. polygons (polygons.cpp) -------------------------------------------------------------------
  bool loop_contains(const Workspace::Loop& outer, const Workspace::Loop& h) const;

  void make_polygons(std::vector<Polygon>& out);

  /// True when a tenth or more of the lower boundary (by plan length) lies in open chains outside
  /// every outer loop and no higher than the loops reach: then the loops miss part of where the
  /// building stands. Open chains inside a loop (a part standing on another) or above every loop
  /// (a balcony, a canopy: floating slabs are local minima too, but not ground) do not count.
  bool open_outside_loops() const;

  // ---- 7c. the lower boundary closed in plan, before the shadow (plan_faces.cpp) ------------------
  /// Every lower-boundary edge in plan, undirected, ends within kPlanGap_m one point, dangling chains
  /// pruned; the union of the bounded faces into `out`. False (out untouched) when over a tenth of
  /// the lower boundary was pruned outside those faces, or no face closed.
  bool close_in_plan(std::vector<Polygon>& out);

  // ---- 8. the shadow: last resort (shadow.cpp) ------------------------------------------------------
  /// Rule 3: the loops miss where the building stands (a mesh full of gaps, walls
  /// on roofs they share no edge with, faces that end short of each other: SketchUp exports). The
  /// shadow, the union of every used facet's vertical projection, is what is certain about where
  /// the building stands: it is the footprint wherever the building does not overhang its base.
  /// The union is the project's exact engine on one footprint; should it fail, the projected facets
  /// go out as they are (overlapping polygons, which the pipeline's union merges anyway).
  void make_shadow(std::vector<Polygon>& out);
};

}  // namespace groundplan::footprint::detail
