// SPDX-License-Identifier: MIT
// Working frame (issue 6): PROJ 9.1 objects behind a pimpl so that no caller sees proj.h.
#include <groundplan/error.h>
#include <groundplan/gis/crs.h>

#include <proj.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>

namespace groundplan::gis {
namespace {

struct PjDeleter {
  void operator()(PJ* p) const {
    if (p) proj_destroy(p);
  }
};
using PjPtr = std::unique_ptr<PJ, PjDeleter>;

bool is_geographic(PJ_TYPE t) { return t == PJ_TYPE_GEOGRAPHIC_2D_CRS || t == PJ_TYPE_GEOGRAPHIC_3D_CRS; }

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

int utm_epsg_for(double lon_deg, double lat_deg) {
  double lon = lon_deg + 180.0;  // 0..360 for -180..180; 180°E itself is the east edge of zone 60
  if (lon < 0 || lon > 360.0) {
    lon = std::fmod(lon, 360.0);
    if (lon < 0) lon += 360.0;
  }
  int zone = std::clamp(static_cast<int>(std::floor(lon / 6.0)) + 1, 1, 60);
  return (lat_deg >= 0 ? 32600 : 32700) + zone;
}

/// A working CRS and the operation from the source into it.
struct FrameTarget {
  PjPtr working;
  PjPtr op;  // null: nothing to transform (a projected metric source, perhaps with swapped axes)
  WorkingCrs crs;
};

// A frame's PROJ objects cost ~100M instructions to make (proj_create_crs_to_crs searches proj.db), as
// much as reading a 3 MB PLATEAU tile; a folder of such tiles paid it once a file. So an Impl outlives
// its frame: it goes back to a pool under its key (the constructor's arguments) and the next frame with
// that key takes it, with the operations already made. An Impl (and so its PJ_CONTEXT) belongs to one
// frame at a time, whichever thread that frame is used on: PROJ's rule (one context per thread at a time)
// holds without tying frames to threads. The operations are made exactly as a fresh frame makes them, so
// results do not depend on reuse.
struct WorkingFrame::Impl {
  PJ_CONTEXT* ctx = nullptr;
  std::string key;
  SrsName source;
  CrsOptions options;
  PjPtr src_h;          // horizontal part of the source CRS
  PJ_TYPE src_type = PJ_TYPE_UNKNOWN;
  bool src_known = false;
  bool src_metric_projected = false;
  bool swap_in = false;  // file writes the other axis order than the CRS's: swap x/y before PROJ
  double z_to_metre = 1;  // heights as written -> metres (the vertical CRS's unit, else the horizontal one's)
  // What the constructor decided, restored for every frame that reuses this Impl:
  std::vector<std::string> base_notes;
  bool base_identity = false;
  bool base_decided = false;
  FrameTarget base;                  // the target CRS or the metric source itself; empty otherwise
  // What decide() made, kept for the next frames: the source -> lon/lat operation and one target per UTM zone.
  PjPtr to_ll;
  bool to_ll_made = false;
  std::map<int, FrameTarget> zones;

  // This frame's state.
  std::string file;
  std::vector<std::string> notes;
  const FrameTarget* current = nullptr;  // null: no working CRS yet (or none: source unknown)
  bool identity = false;
  bool decided = false;

  ~Impl() {
    zones.clear();
    to_ll.reset();
    base = FrameTarget{};
    src_h.reset();
    if (ctx) proj_context_destroy(ctx);
  }

  /// Per-frame state as the constructor left it.
  void begin(const std::string& file_name) {
    file = file_name;
    notes = base_notes;
    identity = base_identity;
    decided = base_decided;
    current = base.working ? &base : nullptr;
  }

  std::string where() const { return file.empty() ? std::string() : file + ": "; }

  PjPtr create(const std::string& def) const {
    if (def.empty()) return nullptr;
    return PjPtr(proj_create(ctx, def.c_str()));
  }

  /// Projected CRS whose first axis unit is the metre.
  bool projected_metric(PJ* crs) const {
    if (proj_get_type(crs) != PJ_TYPE_PROJECTED_CRS) return false;
    PjPtr cs(proj_crs_get_coordinate_system(ctx, crs));
    if (!cs) return false;
    double factor = 0;
    if (!proj_cs_get_axis_info(ctx, cs.get(), 0, nullptr, nullptr, nullptr, &factor, nullptr, nullptr, nullptr))
      return false;
    return std::fabs(factor - 1.0) < 1e-12;
  }

  /// The unit factor (to metres) of axis `axis` of `crs`'s coordinate system; 0 when PROJ does not say.
  double axis_unit(PJ* crs, int axis) const {
    PjPtr cs(crs ? proj_crs_get_coordinate_system(ctx, crs) : nullptr);
    if (!cs || proj_cs_get_axis_count(ctx, cs.get()) <= axis) return 0;
    double factor = 0;
    if (!proj_cs_get_axis_info(ctx, cs.get(), axis, nullptr, nullptr, nullptr, &factor, nullptr, nullptr, nullptr))
      return 0;
    return factor > 0 && std::isfinite(factor) ? factor : 0;
  }

  /// Heights as written -> metres. The vertical CRS decides where the source names one (a compound CRS, or
  /// "EPSG:h+v"): NAVD88 height (ftUS) is in US survey feet. Else a 3D geographic CRS's height axis, else
  /// metres for a 2D geographic CRS (ellipsoidal heights), and the horizontal unit for a projected one:
  /// a file in EPSG:2263 (US survey feet) writes its heights in feet too. `whole`: the source CRS as PROJ
  /// made it (null when it was the horizontal CRS itself, now src_h).
  double height_unit(PJ* whole, std::vector<std::string>& notes) const {
    PjPtr vertical;
    if (whole && proj_get_type(whole) == PJ_TYPE_COMPOUND_CRS) vertical.reset(proj_crs_get_sub_crs(ctx, whole, 1));
    if (!vertical && source.vertical_epsg)
      vertical.reset(proj_create(ctx, ("EPSG:" + std::to_string(source.vertical_epsg)).c_str()));
    double f = 0;
    if (vertical) {
      f = axis_unit(vertical.get(), 0);
    } else if (src_type == PJ_TYPE_GEOGRAPHIC_3D_CRS) {
      f = axis_unit(src_h.get(), 2);
    } else if (src_type == PJ_TYPE_PROJECTED_CRS) {
      f = axis_unit(src_h.get(), 0);
    } else {
      f = 1;
    }
    if (f == 0) {
      notes.push_back("PROJ gives no unit for the heights of \"" + source.text + "\": min_z and max_z kept as written");
      return 1;
    }
    if (std::fabs(f - 1) > 1e-12)
      notes.push_back("heights of \"" + source.text + "\" are in units of " + fmt(f) +
                      " m (" + (vertical ? "its vertical CRS" : "its horizontal unit") + "): converted to metres");
    return f;
  }

  /// Does the CRS put north (latitude/northing) first in its authority axis order?
  bool north_first(PJ* crs) const {
    PjPtr cs(proj_crs_get_coordinate_system(ctx, crs));
    if (!cs) return false;
    const char* dir = nullptr;
    if (!proj_cs_get_axis_info(ctx, cs.get(), 0, nullptr, nullptr, &dir, nullptr, nullptr, nullptr, nullptr))
      return false;
    return dir && (std::string(dir) == "north" || std::string(dir) == "south");
  }

  void fill_crs(FrameTarget& t, const std::string& definition) const {
    crs_known_from(t);
    t.crs.definition = definition;
  }
  void crs_known_from(FrameTarget& t) const {
    WorkingCrs& crs = t.crs;
    PJ* p = t.working.get();
    crs.known = true;
    const char* opts[] = {"MULTILINE=NO", nullptr};
    const char* wkt = proj_as_wkt(ctx, p, PJ_WKT2_2019, opts);
    crs.wkt = wkt ? wkt : "";
    const char* name = proj_get_name(p);
    crs.name = name ? name : "";
    const char* auth = proj_get_id_auth_name(p, 0);
    const char* code = proj_get_id_code(p, 0);
    crs.epsg = auth && code && std::string(auth) == "EPSG" ? std::atoi(code) : 0;
  }

  void make_op(FrameTarget& t) const {
    // Input: as written (authority order for geographic sources, easting first for projected ones;
    // swap_in handles files that say otherwise). Output: normalised, easting first.
    PjPtr src_in(src_type == PJ_TYPE_PROJECTED_CRS ? proj_normalize_for_visualization(ctx, src_h.get())
                                                   : proj_clone(ctx, src_h.get()));
    PjPtr dst(proj_normalize_for_visualization(ctx, t.working.get()));
    if (!src_in || !dst) throw Error(where() + "PROJ could not normalise the axis order of " + source.text);
    // The target is the source CRS itself (a folder's later tiles, in the CRS the first one fixed): nothing to
    // transform, as for the file that fixed it. PROJ's operation between the two would give the same numbers
    // (a no-op), through proj_trans for every vertex: ~0.3 s of CPU on the 1.5 GB city as 16 tiles.
    if (proj_is_equivalent_to(src_in.get(), dst.get(), PJ_COMP_STRICT)) return;
    t.op.reset(proj_create_crs_to_crs_from_pj(ctx, src_in.get(), dst.get(), nullptr, nullptr));
    if (!t.op)
      throw InputError(where() + "PROJ finds no transformation from " + source.text + " to " + t.crs.name +
                       "; name another target with -t_srs");
  }
};

namespace {

std::string frame_key(const std::string& source_srs, const CrsOptions& o) {
  return source_srs + '\n' + o.target_srs + '\n' + std::to_string(static_cast<int>(o.source_axis)) +
         (o.gml_short_epsg_east_first ? "e" : "a");
}

// Trivially destructible, so still readable after the pool is gone at exit.
std::atomic<bool> g_pool_closed{false};
std::atomic<std::size_t> g_setups{0};

/// Impls of finished frames, by key. Bounded: a few per key and thread, few keys.
struct FramePool {
  std::mutex mu;
  std::unordered_map<std::string, std::vector<std::unique_ptr<WorkingFrame::Impl>>> free;
  std::size_t count = 0;
  ~FramePool() { g_pool_closed = true; }
};

std::size_t pool_limit() {
  static const std::size_t n = std::max<std::size_t>(16, 2 * std::thread::hardware_concurrency());
  return n;
}

FramePool& pool() {
  static FramePool p;
  return p;
}

}  // namespace

std::unique_ptr<WorkingFrame::Impl> WorkingFrame::take_pooled(const std::string& key) {
  if (g_pool_closed) return nullptr;
  FramePool& p = pool();
  std::lock_guard<std::mutex> lock(p.mu);
  auto it = p.free.find(key);
  if (it == p.free.end() || it->second.empty()) return nullptr;
  std::unique_ptr<Impl> impl = std::move(it->second.back());
  it->second.pop_back();
  --p.count;
  return impl;
}

void WorkingFrame::give_back(std::unique_ptr<Impl> impl) {
  if (!impl || impl->key.empty() || g_pool_closed) return;
  if (impl->zones.size() > 8) impl->zones.clear();  // a frame that crossed many zones: start again
  std::unique_ptr<Impl> dropped;  // destroyed outside the lock
  FramePool& p = pool();
  std::lock_guard<std::mutex> lock(p.mu);
  if (p.count >= pool_limit()) {
    // Full: make room by dropping an Impl of another key (or this one).
    for (auto it = p.free.begin(); it != p.free.end(); ++it)
      if (!it->second.empty()) {
        dropped = std::move(it->second.back());
        it->second.pop_back();
        if (it->second.empty()) p.free.erase(it);
        --p.count;
        break;
      }
  }
  p.free[impl->key].push_back(std::move(impl));
  ++p.count;
}

WorkingFrame::WorkingFrame(const std::string& source_srs, const CrsOptions& options, const std::string& file) {
  std::string key = frame_key(source_srs, options);
  impl_ = take_pooled(key);
  if (impl_) {
    impl_->begin(file);
    return;
  }
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  m.ctx = proj_context_create();
  if (!m.ctx) throw Error("cannot create a PROJ context");
  proj_log_level(m.ctx, PJ_LOG_NONE);
  m.options = options;
  m.file = file;
  m.source = parse_srs_name(source_srs);
  std::vector<std::string>& notes = m.base_notes;

  if (!m.source.local) {
    PjPtr src = m.create(m.source.definition);
    if (!src) {
      notes.push_back("srsName \"" + source_srs + "\" is not a CRS PROJ knows: coordinates kept as written, CRS unknown");
    } else {
      PJ_TYPE t = proj_get_type(src.get());
      if (t == PJ_TYPE_COMPOUND_CRS) {
        m.src_h.reset(proj_crs_get_sub_crs(m.ctx, src.get(), 0));
      } else if (t == PJ_TYPE_BOUND_CRS) {
        m.src_h.reset(proj_get_source_crs(m.ctx, src.get()));
      } else {
        m.src_h = std::move(src);
      }
      m.src_type = m.src_h ? proj_get_type(m.src_h.get()) : PJ_TYPE_UNKNOWN;
      if (m.src_type == PJ_TYPE_PROJECTED_CRS || is_geographic(m.src_type)) {
        m.src_known = true;
        m.src_metric_projected = m.projected_metric(m.src_h.get());
        m.z_to_metre = m.height_unit(src.get(), notes);
      } else {
        notes.push_back("srsName \"" + source_srs + "\" is neither a projected nor a geographic CRS (" +
                        (m.src_type == PJ_TYPE_GEOCENTRIC_CRS ? "geocentric" : "other") +
                        "): coordinates kept as written, CRS unknown");
        m.src_h.reset();
      }
    }
  } else {
    notes.push_back(source_srs.empty()
                        ? "the file has no srsName: coordinates kept as written, CRS unknown"
                        : "srsName \"" + source_srs + "\" is a CRS local to the file: coordinates kept as written, CRS unknown");
  }
  if (!m.src_known)
    notes.back() += "; the output is labelled an undefined Cartesian SRS (not georeferenced); to georeference it, name "
                    "the CRS the coordinates are in with -a_srs (open option A_SRS), e.g. -a_srs EPSG:25832";

  if (m.src_known) {
    bool authority_north_first = is_geographic(m.src_type) && m.north_first(m.src_h.get());
    // "EPSG:4326" exactly (no URN, no URL): GDAL's GML driver reads it longitude first.
    const std::string& t = m.source.text;
    const bool short_epsg = t.size() > 5 && (t.compare(0, 5, "EPSG:") == 0 || t.compare(0, 5, "epsg:") == 0) &&
                            t.find_first_not_of("0123456789", 5) == std::string::npos;
    switch (options.source_axis) {
      case AxisOrder::Auto:
        m.swap_in = authority_north_first && short_epsg && options.gml_short_epsg_east_first;
        if (m.swap_in)
          notes.push_back("srsName \"" + t + "\" in its short form: read longitude first, as GDAL's GML driver does "
                          "(the URN/URL forms keep EPSG's latitude first); --axis-order north-east if the file "
                          "writes latitude first");
        break;
      case AxisOrder::EastNorth: m.swap_in = authority_north_first; break;
      case AxisOrder::NorthEast: m.swap_in = !authority_north_first && is_geographic(m.src_type); break;
    }
    if (options.source_axis == AxisOrder::NorthEast && m.src_type == PJ_TYPE_PROJECTED_CRS) m.swap_in = true;
  }

  FrameTarget& base = m.base;
  if (!options.target_srs.empty()) {
    if (!m.src_known)
      throw InvalidArgument(m.where() + "a target CRS (" + options.target_srs +
                            ") was asked for, but the source CRS is unknown, so the data cannot be transformed; name it with "
                            "-s_srs (open option S_SRS)");
    SrsName t = parse_srs_name(options.target_srs);
    base.working = m.create(t.definition);
    if (base.working && proj_get_type(base.working.get()) == PJ_TYPE_COMPOUND_CRS)
      base.working.reset(proj_crs_get_sub_crs(m.ctx, base.working.get(), 0));
    if (!base.working || !m.projected_metric(base.working.get()))
      throw InvalidArgument("target CRS \"" + options.target_srs +
                            "\" is not a projected CRS in metres that PROJ knows (ground plans need a metric frame)");
    m.fill_crs(base, t.definition);
    m.make_op(base);
    m.base_identity = !base.op && !m.swap_in;
    m.base_decided = true;
  } else if (m.src_known && m.src_metric_projected) {
    base.working.reset(proj_clone(m.ctx, m.src_h.get()));
    m.crs_known_from(base);
    base.crs.definition = base.crs.epsg ? "EPSG:" + std::to_string(base.crs.epsg) : m.source.definition;
    m.base_identity = !m.swap_in;
    m.base_decided = true;
  } else if (!m.src_known) {
    m.base_identity = true;
    m.base_decided = true;
  }
  m.key = std::move(key);  // made whole: may be reused
  m.begin(file);
  ++g_setups;
}

std::size_t working_frame_setups() { return g_setups.load(); }

WorkingFrame::~WorkingFrame() { give_back(std::move(impl_)); }
WorkingFrame::WorkingFrame(WorkingFrame&&) noexcept = default;
WorkingFrame& WorkingFrame::operator=(WorkingFrame&& other) noexcept {
  if (this != &other) {
    give_back(std::move(impl_));
    impl_ = std::move(other.impl_);
  }
  return *this;
}

void WorkingFrame::decide(double x, double y) {
  Impl& m = *impl_;
  if (m.decided) return;
  // Here the source is known and geographic (or projected in feet): pick the UTM zone of (x, y).
  if (m.swap_in) std::swap(x, y);
  if (!m.to_ll_made) {
    PjPtr src_in(proj_clone(m.ctx, m.src_h.get()));
    PjPtr lonlat(proj_create(m.ctx, "OGC:CRS84"));
    m.to_ll.reset(proj_create_crs_to_crs_from_pj(m.ctx, src_in.get(), lonlat.get(), nullptr, nullptr));
    m.to_ll_made = true;
  }
  PJ* to_ll = m.to_ll.get();
  if (is_geographic(m.src_type)) {
    // Degrees: hundreds of thousands means the label is wrong (projected numbers under a geographic name).
    bool north_first = m.north_first(m.src_h.get());
    double lat = north_first ? x : y, lon = north_first ? y : x;
    if (!(std::fabs(lat) <= 90.0 && std::fabs(lon) <= 360.0))
      throw InputError(m.where() + "srsName \"" + m.source.text + "\" names a geographic CRS (degrees, " +
                       (north_first ? "latitude first" : "longitude first") + ") but the coordinates read " + fmt(x) +
                       ", " + fmt(y) + ", which are no latitude/longitude: the srsName contradicts the data "
                       "(projected coordinates under a geographic label?); name the CRS the coordinates are in with "
                       "-s_srs (open option S_SRS), e.g. -s_srs EPSG:31467");
  }
  PJ_COORD c = proj_coord(x, y, 0, 0);
  PJ_COORD ll = to_ll ? proj_trans(to_ll, PJ_FWD, c) : c;
  if (!to_ll || !std::isfinite(ll.xy.x) || !std::isfinite(ll.xy.y) || std::fabs(ll.xy.y) > 90.0)
    throw InputError(m.where() + "the point " + fmt(x) + ", " + fmt(y) + " is not a valid position in " + m.source.text +
                     ": the srsName contradicts the data; name the CRS the coordinates are in with -s_srs (open "
                     "option S_SRS)");
  int epsg = utm_epsg_for(ll.xy.x, ll.xy.y);
  auto zone = m.zones.find(epsg);
  if (zone == m.zones.end()) {
    FrameTarget t;
    t.working.reset(proj_create(m.ctx, ("EPSG:" + std::to_string(epsg)).c_str()));
    if (!t.working) throw Error("PROJ does not know EPSG:" + std::to_string(epsg) + " (is proj.db installed?)");
    m.fill_crs(t, "EPSG:" + std::to_string(epsg));
    m.make_op(t);
    zone = m.zones.emplace(epsg, std::move(t)).first;
  }
  m.current = &zone->second;
  m.notes.push_back("source CRS " + m.source.text + " is not projected in metres: working CRS is " +
                    m.current->crs.name + " (EPSG:" + std::to_string(epsg) + "), the UTM zone of the data's centre");
  m.decided = true;
}

bool WorkingFrame::decided() const { return impl_->decided; }

bool WorkingFrame::transform_point(double& x, double& y) const {
  const Impl& m = *impl_;
  if (m.identity) return true;
  if (m.swap_in) std::swap(x, y);
  PJ* op = m.current ? m.current->op.get() : nullptr;
  if (!op) return true;  // projected metric source whose axes only needed swapping
  PJ_COORD c = proj_trans(op, PJ_FWD, proj_coord(x, y, 0, 0));
  if (!std::isfinite(c.xy.x) || !std::isfinite(c.xy.y)) return false;
  x = c.xy.x;
  y = c.xy.y;
  return true;
}

bool WorkingFrame::transform(Mesh& mesh, std::string* reason) {
  Impl& m = *impl_;
  if (mesh.vertices.empty()) return true;
  if (m.z_to_metre != 1)
    for (Point3& p : mesh.vertices) p.z *= m.z_to_metre;
  if (m.identity) return true;
  if (!m.decided) {
    double lo_x = mesh.vertices[0].x, hi_x = lo_x, lo_y = mesh.vertices[0].y, hi_y = lo_y;
    for (const Point3& p : mesh.vertices) {
      lo_x = std::min(lo_x, p.x), hi_x = std::max(hi_x, p.x);
      lo_y = std::min(lo_y, p.y), hi_y = std::max(hi_y, p.y);
    }
    decide((lo_x + hi_x) / 2, (lo_y + hi_y) / 2);
  }
  std::vector<Point3>& v = mesh.vertices;
  if (m.swap_in)
    for (Point3& p : v) std::swap(p.x, p.y);
  PJ* op = m.current ? m.current->op.get() : nullptr;
  if (!op) return true;
  const std::size_t n = v.size();
  proj_errno_reset(op);
  proj_trans_generic(op, PJ_FWD, &v[0].x, sizeof(Point3), n, &v[0].y, sizeof(Point3), n, nullptr, 0, 0,
                     nullptr, 0, 0);
  for (const Point3& p : v) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || std::fabs(p.x) > 1e15 || std::fabs(p.y) > 1e15) {
      if (reason)
        *reason = "a vertex cannot be transformed from " + m.source.text + " to " + m.current->crs.name +
                  " (out of the CRS's domain, or the srsName does not fit the coordinates)";
      return false;
    }
  }
  return true;
}

std::string WorkingFrame::area_of_use_mismatch(double x, double y) const {
  const Impl& m = *impl_;
  if (!m.src_known || !m.src_h || !std::isfinite(x) || !std::isfinite(y)) return {};
  double west = 0, south = 0, east = 0, north = 0;
  const char* area = nullptr;
  if (!proj_get_area_of_use(m.ctx, m.src_h.get(), &west, &south, &east, &north, &area) || west <= -1000) return {};
  // The point as the frame reads it (transform(): swap_in, then the CRS's own order for a geographic
  // source, easting first for a projected one) to longitude/latitude on the CRS's own datum: a datum
  // shift is far below the margin, and the operation to OGC:CRS84 costs PROJ ~40 ms to find (per file).
  const bool geographic = is_geographic(m.src_type);
  const bool authority_north_first = geographic && m.north_first(m.src_h.get());
  // Still ~10-40 ms for PROJ to make: kept per thread and source CRS, so a folder of tiles pays it once
  // a thread, not once a file.
  PJ* to_ll = nullptr;
  if (!geographic) {
    struct Cache {
      PJ_CONTEXT* ctx = proj_context_create();
      std::unordered_map<std::string, PjPtr> ops;
      ~Cache() {
        ops.clear();
        if (ctx) proj_context_destroy(ctx);
      }
    };
    thread_local Cache cache;
    if (!cache.ctx) return {};
    auto it = cache.ops.find(m.source.definition);
    if (it == cache.ops.end()) {
      if (cache.ops.size() > 64) cache.ops.clear();
      proj_log_level(cache.ctx, PJ_LOG_NONE);
      PjPtr src(proj_clone(cache.ctx, m.src_h.get()));
      PjPtr src_in(src ? proj_normalize_for_visualization(cache.ctx, src.get()) : nullptr);
      PjPtr base(src ? proj_crs_get_geodetic_crs(cache.ctx, src.get()) : nullptr);
      PjPtr base_ll(base ? proj_normalize_for_visualization(cache.ctx, base.get()) : nullptr);
      PjPtr op(src_in && base_ll ? proj_create_crs_to_crs_from_pj(cache.ctx, src_in.get(), base_ll.get(), nullptr, nullptr)
                                 : nullptr);
      it = cache.ops.emplace(m.source.definition, std::move(op)).first;
    }
    to_ll = it->second.get();
    if (!to_ll) return {};
  }
  constexpr double kMargin = 2.0;  // degrees: "far" outside, not a building on the zone's edge
  auto fits = [&](double a, double b) {
    double lon = authority_north_first ? b : a, lat = authority_north_first ? a : b;
    if (to_ll) {
      PJ_COORD ll = proj_trans(to_ll, PJ_FWD, proj_coord(a, b, 0, 0));
      lon = ll.xy.x, lat = ll.xy.y;
    }
    if (!std::isfinite(lon) || !std::isfinite(lat) || std::fabs(lat) > 90 || std::fabs(lon) > 540) return false;
    if (lat < south - kMargin || lat > north + kMargin) return false;
    if (west <= east) return lon >= west - kMargin && lon <= east + kMargin;
    return lon >= west - kMargin || lon <= east + kMargin;  // across the antimeridian
  };
  double a = x, b = y;
  if (m.swap_in) std::swap(a, b);
  if (fits(a, b)) return {};
  // The order the frame takes the file's numbers in: east first unless the (geographic) CRS or
  // --axis-order says north first.
  const bool reads_north_first = geographic ? m.north_first(m.src_h.get()) != m.swap_in : m.swap_in;
  std::string cause;
  if (fits(b, a)) {
    cause = std::string("the axes look swapped (the point fits when its two numbers are exchanged): pass --axis-order ") +
            (reads_north_first ? "east-north" : "north-east");
  } else if (!geographic && std::fabs(x) <= 360 && std::fabs(y) <= 360) {
    cause = "the numbers look like degrees under a projected (metre) label: name their CRS with -s_srs, e.g. "
            "-s_srs EPSG:4326 (with --axis-order east-north if longitude comes first)";
  } else if (geographic) {
    cause = "the numbers do not look like degrees of that area (metres under a geographic label?): name their CRS "
            "with -s_srs, e.g. -s_srs EPSG:25832";
  } else {
    cause = "the srsName does not fit the coordinates: name their CRS with -s_srs";
  }
  return "WARNING: the coordinates " + fmt(x) + ", " + fmt(y) + " lie far outside the area of use of " + m.source.text +
         " (" + (area ? std::string(area).substr(0, 120) : std::string("?")) + ": longitude " + fmt(west) + " to " +
         fmt(east) + ", latitude " + fmt(south) + " to " + fmt(north) + "); " + cause;
}

bool WorkingFrame::source_known() const { return impl_->src_known; }
bool WorkingFrame::source_geographic() const { return is_geographic(impl_->src_type); }
bool WorkingFrame::identity() const { return impl_->identity && impl_->z_to_metre == 1; }
double WorkingFrame::height_to_metre() const { return impl_->z_to_metre; }
const SrsName& WorkingFrame::source() const { return impl_->source; }
const WorkingCrs& WorkingFrame::working_crs() const {
  static const WorkingCrs kNone;
  return impl_->current ? impl_->current->crs : kNone;
}
const std::vector<std::string>& WorkingFrame::notes() const { return impl_->notes; }

}  // namespace groundplan::gis
