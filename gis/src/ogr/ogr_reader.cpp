// SPDX-License-Identifier: MIT
// Any OGR layer as input (issue 22): features -> meshes, one source CRS per file. GDAL does the
// reading (every format it knows); this file only decides what a feature is to the ground plans.
#include <groundplan/error.h>
#include <groundplan/gis/ogr_input.h>
#include <groundplan/ring_normal.h>

#include "coordinate_limit.h"
#include "files_read.h"
#include "ogr/ogr_source.h"

#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <unordered_map>
#include <utility>

namespace groundplan::gis {
namespace {

using ogr_detail::LayerPlan;

constexpr const char* kOwnDriver = "GroundPlan";
constexpr double kPi = 3.14159265358979323846;
constexpr double kHorizontalToleranceDeg = 10.0;  // as FootprintParams::horizontal_tolerance_deg

/// GDAL's drivers, once per process (the CLI and the plugin have registered them already; a library
/// caller may not have). GDALAllRegister is not safe to run on several threads at once: a static's
/// initialisation is.
void ensure_registered() {
  static const bool registered = [] {
    if (GDALGetDriverCount() == 0) GDALAllRegister();
    return true;
  }();
  (void)registered;
}

/// Every vector driver but ours, for GDALOpenEx / GDALIdentifyDriverEx: GROUNDPLAN:x must never come
/// back here (recursion), and a raster driver has no features.
CPLStringList vector_drivers() {
  CPLStringList names;
  GDALDriverManager* dm = GetGDALDriverManager();
  for (int i = 0; i < dm->GetDriverCount(); ++i) {
    GDALDriver* d = dm->GetDriver(i);
    if (!d || EQUAL(d->GetDescription(), kOwnDriver)) continue;
    if (!d->GetMetadataItem(GDAL_DCAP_VECTOR)) continue;
    names.AddString(d->GetDescription());
  }
  return names;
}

/// "EPSG:n" when the CRS is one, else WKT2: what parse_srs_name / PROJ take.
std::string srs_definition(const OGRSpatialReference& srs) {
  const char* auth = srs.GetAuthorityName(nullptr);
  const char* code = srs.GetAuthorityCode(nullptr);
  if (auth && code && EQUAL(auth, "EPSG")) return std::string("EPSG:") + code;
  char* wkt = nullptr;
  const char* const opts[] = {"FORMAT=WKT2_2019", nullptr};
  std::string out;
  if (srs.exportToWkt(&wkt, opts) == OGRERR_NONE && wkt) out = wkt;
  CPLFree(wkt);
  return out;
}

/// Whether the layer's data x axis is east (longitude, easting): GDAL's data-axis-to-CRS-axis mapping.
bool data_east_north(const OGRSpatialReference& srs) {
  const std::vector<int>& map = srs.GetDataAxisToSRSAxisMapping();
  const int axis = map.empty() ? 1 : std::abs(map[0]);
  OGRAxisOrientation orient = OAO_Other;
  srs.GetAxis(nullptr, axis - 1, &orient);
  return orient != OAO_North && orient != OAO_South;
}

/// One feature's geometry as mesh faces (rings without the closing vertex), written straight into the
/// mesh's flat arrays: a million footprints are a million small meshes, so no per-ring vectors.
struct Faces {
  Mesh mesh;                  // faces of kind FootPrint until classify() says otherwise
  std::size_t non_areal = 0;  // points / lines met
  bool non_finite = false;
  double max_abs = 0;
};

void add_ring(const OGRLinearRing* ring, Faces& out) {
  Mesh& m = out.mesh;
  const int n = ring ? ring->getNumPoints() : 0;
  int last = n;
  if (n > 1 && ring->getX(0) == ring->getX(n - 1) && ring->getY(0) == ring->getY(n - 1) &&
      ring->getZ(0) == ring->getZ(n - 1))
    last = n - 1;  // the closing vertex
  m.vertices.reserve(m.vertices.size() + static_cast<std::size_t>(std::max(last, 0)));
  for (int i = 0; i < last; ++i) {
    const Point3 p{ring->getX(i), ring->getY(i), ring->getZ(i)};
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) out.non_finite = true;
    out.max_abs = std::max({out.max_abs, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    m.indices.push_back(static_cast<std::uint32_t>(m.vertices.size()));
    m.vertices.push_back(p);
  }
  m.ring_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()));
}

void add_polygon(const OGRPolygon* poly, Faces& out) {
  MeshFace f;
  f.first_ring = static_cast<std::uint32_t>(out.mesh.ring_count());
  f.ring_count = static_cast<std::uint32_t>(1 + poly->getNumInteriorRings());
  f.kind = SurfaceKind::FootPrint;
  f.lod = 0;
  add_ring(poly->getExteriorRing(), out);
  for (int i = 0; i < poly->getNumInteriorRings(); ++i) add_ring(poly->getInteriorRing(i), out);
  out.mesh.faces.push_back(f);
}

void collect(const OGRGeometry* g, Faces& out, int depth) {
  if (!g || g->IsEmpty() || depth > 32) return;
  switch (wkbFlatten(g->getGeometryType())) {
    case wkbPolygon:
    case wkbTriangle:
      add_polygon(g->toPolygon(), out);
      break;
    case wkbPolyhedralSurface:
    case wkbTIN: {
      const auto* ps = g->toPolyhedralSurface();
      for (int i = 0; i < ps->getNumGeometries(); ++i) collect(ps->getGeometryRef(i), out, depth + 1);
      break;
    }
    case wkbMultiPolygon:
    case wkbGeometryCollection:
    case wkbMultiSurface: {
      const auto* gc = g->toGeometryCollection();
      for (int i = 0; i < gc->getNumGeometries(); ++i) collect(gc->getGeometryRef(i), out, depth + 1);
      break;
    }
    default:  // points, lines (curves are linearised before)
      ++out.non_areal;
      break;
  }
}

/// True when ring r is horizontal within the footprint's tolerance (Newell's normal), or has no area.
bool horizontal(const Mesh& m, std::uint32_t r) {
  const std::uint32_t a = m.ring_offsets[r], b = m.ring_offsets[r + 1];
  if (b - a < 3) return true;
  const Point3 n = ring_normal(m, r);
  const double nx = n.x, ny = n.y, nz = n.z;
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  return len == 0 || std::fabs(nz) >= std::cos(kHorizontalToleranceDeg * kPi / 180.0) * len;
}

/// FootPrint faces when all are horizontal (a footprint given outright), else Unknown (a solid or
/// surface: its bottom, or decomposition).
void classify(Mesh& m, bool is_3d) {
  if (!is_3d) return;
  for (const MeshFace& f : m.faces)
    if (!horizontal(m, f.first_ring)) {
      for (MeshFace& g : m.faces) {
        g.kind = SurfaceKind::Unknown;
        g.lod = 255;
      }
      return;
    }
}

/// Appends the faces of `from` to `to` (a --group-by building).
void append_mesh(const Mesh& from, Mesh& to) {
  const auto v0 = static_cast<std::uint32_t>(to.vertices.size());
  const auto i0 = static_cast<std::uint32_t>(to.indices.size());
  const auto r0 = static_cast<std::uint32_t>(to.ring_count());
  to.vertices.insert(to.vertices.end(), from.vertices.begin(), from.vertices.end());
  for (std::uint32_t i : from.indices) to.indices.push_back(v0 + i);
  for (std::size_t r = 1; r < from.ring_offsets.size(); ++r) to.ring_offsets.push_back(i0 + from.ring_offsets[r]);
  for (MeshFace f : from.faces) {
    f.first_ring += r0;
    to.faces.push_back(f);
  }
}

/// The CRS of the layer's geometry field `geom`; null when it has none, GeoPackage's "Undefined
/// geographic/cartesian SRS" included (srs_id 0 / -1: the writer knew no CRS, so reading its numbers as
/// degrees would be a guess).
const OGRSpatialReference* layer_srs(OGRLayer* layer, int geom) {
  OGRFeatureDefn* defn = layer->GetLayerDefn();
  const OGRSpatialReference* srs = geom >= 0 && geom < defn->GetGeomFieldCount()
                                       ? defn->GetGeomFieldDefn(geom)->GetSpatialRef() : layer->GetSpatialRef();
  if (!srs || srs->IsEmpty()) return nullptr;
  const char* name = srs->GetName();
  if (!srs->GetAuthorityName(nullptr) && name && STARTS_WITH_CI(name, "Undefined ")) return nullptr;
  return srs;
}

/// --input-geom-field: the geometry field each layer reads (the first when not named, or when a layer
/// lacks the named one but another has it); a NOTE for every layer whose other geometry fields are left.
void choose_geometry_fields(std::vector<LayerPlan>& plans, const std::string& field, const std::string& path,
                            std::vector<Problem>& problems) {
  auto names = [](OGRFeatureDefn* defn) {
    std::string out;
    for (int k = 0; k < defn->GetGeomFieldCount() && k < 40; ++k)
      out += (k ? ", " : "") + std::string("'") + defn->GetGeomFieldDefn(k)->GetNameRef() + "'";
    return out.empty() ? std::string("none") : out;
  };
  bool anywhere = field.empty();
  for (LayerPlan& p : plans) {
    p.geom_index = field.empty() ? 0 : p.layer->GetLayerDefn()->GetGeomFieldIndex(field.c_str());
    anywhere = anywhere || p.geom_index >= 0;
  }
  if (!anywhere)
    throw InputError(path + ": layer '" + plans.front().name + "' has no geometry field '" + field +
                     "' (--input-geom-field); its geometry fields: " + names(plans.front().layer->GetLayerDefn()));
  for (LayerPlan& p : plans) {
    OGRFeatureDefn* defn = p.layer->GetLayerDefn();
    if (p.geom_index < 0) {
      p.geom_index = 0;
      problems.push_back({"", path, "read", "NOTE", "layer '" + p.name + "' has no geometry field '" + field +
                                                        "' (--input-geom-field): its first one is read"});
    }
    if (defn->GetGeomFieldCount() > 1)
      problems.push_back({"", path, "read", "NOTE",
                          "layer '" + p.name + "' has " + std::to_string(defn->GetGeomFieldCount()) +
                              " geometry fields (" + names(defn) + "): only '" +
                              defn->GetGeomFieldDefn(p.geom_index)->GetNameRef() +
                              "' is read, the others are ignored (--input-geom-field NAME chooses)"});
  }
}

/// The index of `field` in the layer, -1 when absent (or not asked for).
int field_index(OGRLayer* layer, const std::string& field) {
  return field.empty() ? -1 : layer->GetLayerDefn()->GetFieldIndex(field.c_str());
}

/// `field` must be in one of the layers at least (a layer without it uses the FID, with a note).
void check_field(const std::vector<LayerPlan>& plans, const std::string& field, int LayerPlan::*index,
                 const std::string& path, const char* flag, std::vector<Problem>& problems) {
  if (field.empty()) return;
  const bool anywhere = std::any_of(plans.begin(), plans.end(), [&](const LayerPlan& p) { return p.*index >= 0; });
  if (!anywhere) {
    OGRFeatureDefn* defn = plans.front().layer->GetLayerDefn();
    std::string fields;
    for (int k = 0; k < defn->GetFieldCount() && k < 40; ++k)
      fields += (k ? ", " : "") + std::string(defn->GetFieldDefn(k)->GetNameRef());
    throw InputError(path + ": layer '" + plans.front().name + "' has no field '" + field + "' (" + flag +
                     "); its fields: " + (fields.empty() ? "none" : fields));
  }
  for (const LayerPlan& p : plans)
    if (p.*index < 0)
      problems.push_back({"", path, "read", "NOTE",
                          "layer '" + p.name + "' has no field '" + field + "' (" + flag + "): its features are named by their FID"});
}

}  // namespace

bool looks_like_connection_string(const std::string& path) {
  const auto colon = path.find(':');
  if (colon == std::string::npos || colon < 2) return false;  // "C:\..." is a drive letter
  if (path.compare(0, 4, "/vsi") == 0) return false;
  for (std::size_t i = 0; i < colon; ++i)
    if (!std::isalnum(static_cast<unsigned char>(path[i])) && path[i] != '_') return false;
  return true;
}

bool ogr_can_read(const std::string& path) {
  try {
    ensure_registered();
    const CPLStringList drivers = vector_drivers();
    CPLErrorStateBackuper keep_last_error;
    CPLPushErrorHandler(CPLQuietErrorHandler);
    const bool found = GDALIdentifyDriverEx(path.c_str(), GDAL_OF_VECTOR, drivers.List(), nullptr) != nullptr;
    CPLPopErrorHandler();
    return found;
  } catch (...) {
    return false;
  }
}


namespace ogr_detail {

namespace {
LayerPlan layer_plan(OGRLayer* layer, std::string name) {
  LayerPlan p;
  p.layer = layer;
  p.name = std::move(name);
  return p;
}
}  // namespace

ErrorCollector::ErrorCollector() { CPLPushErrorHandlerEx(&ErrorCollector::handler, this); }
ErrorCollector::~ErrorCollector() { CPLPopErrorHandler(); }

std::string ErrorCollector::take() {
  std::string out;
  for (const std::string& m : messages_) out += (out.empty() ? "" : "; ") + m;
  if (dropped_) out += "; and " + std::to_string(dropped_) + " more GDAL messages";
  messages_.clear();
  dropped_ = 0;
  failure_ = false;
  return out;
}

void CPL_STDCALL ErrorCollector::handler(CPLErr cls, CPLErrorNum, const char* msg) {
  auto* self = static_cast<ErrorCollector*>(CPLGetErrorHandlerUserData());
  if (!self || cls == CE_Debug) return;
  if (cls >= CE_Failure) self->failure_ = true;
  if (self->messages_.size() < 5)
    self->messages_.emplace_back(std::string(cls >= CE_Failure ? "GDAL error: " : "GDAL warning: ") + (msg ? msg : ""));
  else
    ++self->dropped_;
}

void open_source(const std::string& path, const OgrInputOptions& options, Source& src, std::vector<Problem>& problems,
                 OgrInfo& info) {
  ensure_registered();
  ErrorCollector& errors = src.errors;
  const CPLStringList drivers = vector_drivers();
  CPLStringList open_options;
  for (const std::string& o : options.open_options) open_options.AddString(o.c_str());
  src.ds.reset(GDALDataset::FromHandle(
      GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, drivers.List(), open_options.List(), nullptr)));
  if (!src.ds) {
    const std::string why = errors.take();
    // A damaged .shx index: GDAL can rebuild it from the .shp (it writes a new .shx), but only when asked.
    const bool shx = why.find(".shx") != std::string::npos;
    throw InputError(path + ": GDAL cannot open it as a vector source" + (why.empty() ? "" : " (" + why + ")") +
                     (shx ? "; if the .shx index is damaged, --config SHAPE_RESTORE_SHX YES rebuilds it from the .shp" : ""));
  }
  GDALDataset* ds = src.ds.get();
  if (GDALDriver* d = ds->GetDriver()) info.driver = d->GetDescription();
  {  // the dataset's files (a shapefile's .shp, .shx, .dbf, .prj ...): the result cache keys on them
    const CPLStringList files(ds->GetFileList());
    for (int i = 0; i < files.size(); ++i) note_file_opened(files[i]);
  }

  // The layers to read: an SQL result, the named ones, or all.
  std::vector<LayerPlan>& plans = src.plans;
  if (!options.sql.empty() && (!options.where.empty() || !options.layers.empty()))
    throw InputError(path + ": --input-sql names its own layer and condition: --input-layer and --input-where "
                          "do not apply to it (put them in the statement)");
  if (!options.sql.empty()) {
    src.sql_layer = ds->ExecuteSQL(options.sql.c_str(), nullptr, options.dialect.empty() ? nullptr : options.dialect.c_str());
    if (!src.sql_layer) {
      const std::string why = errors.take();
      throw InputError(path + ": --input-sql gave no layer" + (why.empty() ? "" : " (" + why + ")") + ": " + options.sql);
    }
    plans.push_back(layer_plan(src.sql_layer, src.sql_layer->GetName()));
  } else if (!options.layers.empty()) {
    for (const std::string& name : options.layers) {
      OGRLayer* l = ds->GetLayerByName(name.c_str());
      if (!l) {
        std::string names;
        for (int i = 0; i < ds->GetLayerCount() && i < 40; ++i) names += (i ? ", " : "") + std::string(ds->GetLayer(i)->GetName());
        throw InputError(path + ": has no layer '" + name + "' (--input-layer); its layers: " + (names.empty() ? "none" : names));
      }
      plans.push_back(layer_plan(l, name));
    }
  } else {
    for (int i = 0; i < ds->GetLayerCount(); ++i) plans.push_back(layer_plan(ds->GetLayer(i), ds->GetLayer(i)->GetName()));
  }
  if (plans.empty()) throw InputError(path + ": GDAL (" + info.driver + ") opens it, but it has no vector layer");

  // One source CRS per file: the first layer's that has one; others are transformed into it.
  std::unique_ptr<OGRSpatialReference> source;
  for (LayerPlan& p : plans) {
    if (!options.where.empty() && options.sql.empty() && p.layer->SetAttributeFilter(options.where.c_str()) != OGRERR_NONE) {
      const std::string why = errors.take();
      throw InputError(path + ": layer '" + p.name + "' refuses --input-where '" + options.where + "'" +
                       (why.empty() ? "" : " (" + why + ")"));
    }
    p.id_index = field_index(p.layer, options.id_field);
    p.group_index = field_index(p.layer, options.group_by);
    info.layers.push_back(p.name);
  }
  check_field(plans, options.id_field, &LayerPlan::id_index, path, "--id-field", problems);
  check_field(plans, options.group_by, &LayerPlan::group_index, path, "--group-by", problems);
  choose_geometry_fields(plans, options.geom_field, path, problems);
  for (LayerPlan& p : plans) {
    const OGRSpatialReference* srs = layer_srs(p.layer, p.geom_index);
    if (srs && !source) source.reset(srs->Clone());
  }
  if (source) {
    info.source_srs = srs_definition(*source);
    info.east_north = data_east_north(*source);
    for (LayerPlan& p : plans) {
      const OGRSpatialReference* srs = layer_srs(p.layer, p.geom_index);
      if (!srs) {
        p.no_crs = true;
      } else if (!srs->IsSame(source.get())) {
        p.to_source.reset(OGRCreateCoordinateTransformation(srs, source.get()));
        if (!p.to_source)
          throw InputError(path + ": layer '" + p.name + "' is in a CRS that cannot be transformed into the first "
                           "layer's (" + info.source_srs.substr(0, 80) + "): " + errors.take());
      }
    }
  }
  if (const std::string said = errors.take(); !said.empty()) problems.push_back({"", path, "read", "NOTE", said});
}

void FeatureReader::read(LayerPlan& p, OGRFeature& feature) {
  ++info_.features;
  ++layer_features_;
  const GIntBig fid = feature.GetFID();
  const std::string fid_text = fid == OGRNullFID ? std::string("(no FID)") : std::to_string(fid);
  std::string id;
  if (p.id_index >= 0 && feature.IsFieldSetAndNotNull(p.id_index)) id = feature.GetFieldAsString(p.id_index);
  if (id.empty()) id = prefix_layer_ ? p.name + ":" + fid_text : fid_text;
  std::optional<std::string> group;
  if (p.group_index >= 0 && feature.IsFieldSetAndNotNull(p.group_index)) group = feature.GetFieldAsString(p.group_index);
  auto building = [&] { return group ? *group : id; };  // before id moves into the mesh
  auto where = [&] { return "layer '" + p.name + "', FID " + fid_text + ": "; };
  const std::string gdal = src_.errors.take();
  auto bad = [&](const char* code, const std::string& what) {
    ++info_.features_bad;
    problems_.push_back({building(), path_, "read", code, where() + what + (gdal.empty() ? "" : " (" + gdal + ")")});
  };

  OGRGeometry* geom = feature.GetGeomFieldRef(p.geom_index);
  if (!geom || geom->IsEmpty()) return bad("EMPTY_GEOMETRY", "the feature has no geometry (null or empty)");
  if (p.no_crs)
    return bad("NO_CRS", "the layer has no CRS while the file's others have " + info_.source_srs.substr(0, 60) +
                             ": its coordinates cannot be placed");
  std::unique_ptr<OGRGeometry> owned;
  if (geom->hasCurveGeometry()) {
    owned.reset(geom->getLinearGeometry());
    if (!owned) return bad("BAD_GEOMETRY", "the curve geometry could not be linearised");
    geom = owned.get();
  }
  if (p.to_source) {
    if (!owned) {
      owned.reset(geom->clone());
      geom = owned.get();
    }
    if (geom->transform(p.to_source.get()) != OGRERR_NONE)
      return bad("TRANSFORM_FAILED", "its coordinates cannot be transformed into the file's CRS");
  }
  Faces f;
  collect(geom, f, 0);
  if (f.mesh.faces.empty())
    return bad("NOT_AREAL", std::string("a ") + OGRGeometryTypeToName(geom->getGeometryType()) +
                                " has no area: only polygons and surfaces are footprints");
  if (f.non_finite) return bad("BAD_COORDINATES", "a coordinate is NaN or infinite");
  if (f.max_abs > options_.max_abs_coordinate)
    return bad("COORDINATE_OUT_OF_RANGE", beyond_coordinate_limit(f.max_abs, options_.max_abs_coordinate));
  if (f.mesh.vertices.size() > options_.max_vertices)
    return bad("TOO_MANY_VERTICES", std::to_string(f.mesh.vertices.size()) + " vertices, more than the limit of " +
                                        std::to_string(options_.max_vertices));
  if (!gdal.empty())  // GDAL said something about a feature it still gave: kept, and said
    problems_.push_back({building(), path_, "read", "NOTE", where() + gdal});
  if (f.non_areal)
    problems_.push_back({building(), path_, "read", "NON_AREAL_PARTS",
                         where() + std::to_string(f.non_areal) + " point or line parts of the geometry are left out "
                                 "(no area); its polygons are used"});
  classify(f.mesh, geom->Is3D());
  if (group) {
    auto [it, fresh] = group_of_.try_emplace(*group, groups_.size());
    if (fresh) {
      Mesh& m = groups_.emplace_back();
      m.source_id = *group;
      m.source_file = path_;
      m.name = p.name;
    }
    append_mesh(f.mesh, groups_[it->second]);
    return;
  }
  Mesh& m = f.mesh;
  m.source_id = std::move(id);
  m.source_file = path_;
  m.name = p.name;
  ++info_.buildings;
  on_mesh_(std::move(m));
}

void FeatureReader::layer_stopped(const LayerPlan& p) {
  const std::size_t read = std::exchange(layer_features_, 0);
  // A GDAL failure that ended the layer (a cut-short file ...): say so; features after it are not read.
  if (!src_.errors.failure()) {
    const std::string warnings = src_.errors.take();
    if (!warnings.empty()) problems_.push_back({"", path_, "read", "NOTE", "layer '" + p.name + "': " + warnings});
    return;
  }
  const std::string why = src_.errors.take();
  // How many are lost, where the layer knows its count (a shapefile's .shx, a GeoPackage's contents table).
  std::string of;
  if (p.layer->TestCapability(OLCFastFeatureCount)) {
    const GIntBig n = p.layer->GetFeatureCount(FALSE);
    if (n >= 0 && static_cast<std::size_t>(n) >= read)
      of = " of the " + std::to_string(n) + " the layer counts (" + std::to_string(static_cast<std::size_t>(n) - read) +
           " not read)";
    src_.errors.take();
  }
  problems_.push_back({"", path_, "read", "UNREADABLE_FEATURES",
                       "layer '" + p.name + "': reading stopped after " + std::to_string(read) + " features" + of +
                           ": " + why});
}

void FeatureReader::deliver_groups() {
  for (Mesh& m : groups_) {
    ++info_.buildings;
    on_mesh_(std::move(m));
  }
  groups_.clear();
}

}  // namespace ogr_detail

void read_ogr(const std::string& path, const OgrInputOptions& options, const std::function<void()>& source_srs_ready,
              const std::function<void(Mesh&&)>& on_mesh, std::vector<Problem>& problems, OgrInfo& info) {
  info = OgrInfo{};
  ogr_detail::Source src;
  ogr_detail::open_source(path, options, src, problems, info);
  if (source_srs_ready) source_srs_ready();
  ogr_detail::FeatureReader reader(path, options, src, on_mesh, problems, info);
  GDALDataset* ds = src.ds.get();
  if (ds->TestCapability(ODsCRandomLayerRead) && options.sql.empty()) {
    // OSM and other interleaved formats: features come in file order from any layer.
    std::unordered_map<OGRLayer*, LayerPlan*> wanted;
    for (LayerPlan& p : src.plans) wanted[p.layer] = &p;
    ds->ResetReading();
    for (;;) {
      OGRLayer* from = nullptr;
      std::unique_ptr<OGRFeature> feature(ds->GetNextFeature(&from, nullptr, nullptr, nullptr));
      if (!feature) break;
      auto it = wanted.find(from);
      if (it == wanted.end()) continue;
      reader.read(*it->second, *feature);
    }
    reader.layer_stopped(src.plans.front());
  } else {
    for (LayerPlan& p : src.plans) {
      p.layer->ResetReading();
      for (;;) {
        std::unique_ptr<OGRFeature> feature(p.layer->GetNextFeature());
        if (!feature) break;
        reader.read(p, *feature);
      }
      reader.layer_stopped(p);
    }
  }
  reader.deliver_groups();
}

}  // namespace groundplan::gis
