// SPDX-License-Identifier: MIT
// Format dispatch (issue 6): CityGML passes through as written; KML/KMZ, COLLADA and glTF carry
// their own georeference and are placed here, so the pipeline sees meshes in the working CRS.
#include <groundplan/error.h>
#include <groundplan/gis/collada.h>
#include <groundplan/gis/placement.h>
#include <groundplan/gis/reader.h>
#include <groundplan/gis/tiles3d.h>

#include <cpl_conv.h>
#include <cpl_vsi.h>

#include "citygml/in_memory.h"
#include "cityjson/read_into.h"
#include "gzip_progress.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <optional>

namespace groundplan::gis {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool ends_with(const std::string& s, std::string_view tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string extension(const std::string& name) {
  const auto slash = name.find_last_of("/\\");
  const auto dot = name.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  return lower(name.substr(dot));
}

InputFormat sniff(std::string_view head) {
  if (head.size() >= 4 && std::memcmp(head.data(), "PK\x03\x04", 4) == 0) return InputFormat::Kmz;
  if (head.size() >= 4 && std::memcmp(head.data(), "glTF", 4) == 0) return InputFormat::Glb;
  for (const char* magic : {"b3dm", "cmpt", "i3dm", "pnts"})  // i3dm, pnts: the 3D Tiles reader says they are not read
    if (head.size() >= 4 && std::memcmp(head.data(), magic, 4) == 0) return InputFormat::Tiles3d;
  const auto first = head.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (first == std::string_view::npos) return InputFormat::Unknown;
  if (head[first] == '{') {
    bool sequence = false;
    if (looks_like_cityjson(head, &sequence)) return sequence ? InputFormat::CityJsonSeq : InputFormat::CityJson;
    if (looks_like_tileset(head)) return InputFormat::Tiles3d;
    return head.find("\"asset\"") != std::string_view::npos ? InputFormat::Gltf : InputFormat::Unknown;
  }
  if (head[first] != '<') return InputFormat::Unknown;
  if (looks_like_citygml(head)) return InputFormat::CityGml;
  if (head.find("<COLLADA") != std::string_view::npos) return InputFormat::Collada;
  if (head.find("<kml") != std::string_view::npos || head.find(":kml") != std::string_view::npos) return InputFormat::Kml;
  if (head.find("http://www.opengis.net/citygml/") != std::string_view::npos) return InputFormat::CityGml;
  return InputFormat::Unknown;
}

/// `name` less a trailing ".gz" when it names a gzip input; else `name`.
std::string without_gz(const std::string& name) {
  return is_gzip_input_name(name) ? name.substr(0, name.size() - 3) : name;
}

std::string read_head(const std::string& path) {
  std::string head(4096, '\0');
  VSILFILE* f = VSIFOpenL(open_path(path).c_str(), "rb");
  if (!f) return {};
  head.resize(VSIFReadL(head.data(), 1, head.size(), f));
  VSIFCloseL(f);
  return head;
}

}  // namespace

const char* to_string(InputFormat f) {
  switch (f) {
    case InputFormat::Unknown: return "unknown";
    case InputFormat::CityGml: return "CityGML";
    case InputFormat::Kml: return "KML";
    case InputFormat::Kmz: return "KMZ";
    case InputFormat::Collada: return "COLLADA";
    case InputFormat::Gltf: return "glTF";
    case InputFormat::Glb: return "GLB";
    case InputFormat::CityJson: return "CityJSON";
    case InputFormat::CityJsonSeq: return "CityJSONSeq";
    case InputFormat::Ogr: return "OGR";
    case InputFormat::Tiles3d: return "3D Tiles";
  }
  return "?";
}

namespace {
// The names a folder or a zip of tiles is expanded to: one list for the checks and for the messages that
// name them. Gzip: the text formats, with ".gz" after them.
constexpr std::string_view kInputSuffixes[] = {".gml", ".citygml", ".xml", ".kml", ".kmz", ".gltf", ".glb",
                                               ".b3dm", ".i3dm", ".cmpt", ".city.json", ".city.jsonl"};
constexpr std::string_view kGzipSuffixes[] = {".gml", ".citygml", ".xml", ".kml", ".city.json", ".city.jsonl"};

template <std::size_t N>
bool has_suffix(const std::string& lowered, const std::string_view (&suffixes)[N]) {
  for (std::string_view s : suffixes)
    if (ends_with(lowered, s)) return true;
  return false;
}
}  // namespace

std::string input_name_patterns() {
  std::string out;
  for (std::string_view s : kInputSuffixes) out += (out.empty() ? "*" : ", *") + std::string(s);
  for (std::string_view s : kGzipSuffixes) out += ", *" + std::string(s) + ".gz";
  return out;
}

bool is_gzip_input_name(const std::string& name) {
  const std::string l = lower(name);
  return ends_with(l, ".gz") && has_suffix(l.substr(0, l.size() - 3), kGzipSuffixes);
}

std::string open_path(const std::string& path) {
  if (!is_gzip_input_name(path) || path.rfind("/vsi", 0) == 0) return path;
  return "/vsigzip/" + path;
}

InputFormat detect_format(const std::string& gz_name, std::string_view head) {
  const std::string name = without_gz(gz_name);
  const std::string ext = extension(name);
  if (ext == ".gml" || ext == ".citygml") return InputFormat::CityGml;
  if (ext == ".kml") return InputFormat::Kml;
  if (ext == ".kmz") return InputFormat::Kmz;  // not a zip: the KML reader says so
  if (ext == ".dae") return InputFormat::Collada;
  if (ext == ".gltf") return InputFormat::Gltf;
  if (ext == ".glb") return InputFormat::Glb;
  if (ext == ".b3dm" || ext == ".cmpt" || ext == ".i3dm" || ext == ".pnts") return InputFormat::Tiles3d;
  if (lower(name) == "tileset.json" || ends_with(lower(name), "/tileset.json") || ends_with(lower(name), "\\tileset.json"))
    return InputFormat::Tiles3d;
  if (ext == ".jsonl") return InputFormat::CityJsonSeq;  // the reader says when it is not CityJSONSeq
  if (ends_with(lower(name), ".city.json")) return InputFormat::CityJson;
  const InputFormat by_content = sniff(head);
  if (ext == ".xml" && by_content == InputFormat::Unknown) return InputFormat::CityGml;  // NOT_CITYGML if not
  // A zip named .zip / .shz is no KMZ: GDAL reads zipped shapefiles (parts.shp.zip) and the like (issue 22).
  if (by_content == InputFormat::Kmz && (ext == ".zip" || ext == ".shz")) return InputFormat::Unknown;
  return by_content;
}

InputFormat detect_format(const std::string& path) {
  const std::string ext = extension(without_gz(path));
  if (!ext.empty() && ext != ".xml" && ext != ".json") {
    const InputFormat f = detect_format(path, std::string_view());
    if (f != InputFormat::Unknown) return f;
  }
  return detect_format(path, read_head(path));
}

bool is_input_name(const std::string& name) {
  return is_gzip_input_name(name) || has_suffix(lower(name), kInputSuffixes);
}

void read_any(const std::string& path, const ReadOptions& options, const MeshCallback& on_mesh,
              std::vector<Problem>& problems, ReadInfo& info) {
  info = ReadInfo{};
  info.file = path;
  info.format = detect_format(path);
  if (info.format == InputFormat::Unknown && ogr_can_read(path)) info.format = InputFormat::Ogr;
  if (info.format == InputFormat::Unknown) {
    VSIStatBufL st;
    if (VSIStatL(path.c_str(), &st) != 0 && !looks_like_connection_string(path))
      throw InputError(path + ": cannot open the file (does it exist and is it readable?)");
    throw InputError(path + ": format not recognised (CityGML .gml/.citygml/.xml, KML .kml/.kmz, glTF .gltf/.glb, "
                            "3D Tiles tileset.json/.b3dm/.cmpt, COLLADA .dae, CityJSON .city.json/.json, CityJSONSeq .city.jsonl, and any vector format GDAL "
                            "reads: none of them knows it)");
  }
  // A gzip input is read through /vsigzip/, and no further than gzip_max_ratio times its packed size.
  const std::string open = open_path(path);
  std::uint64_t max_bytes = 0;  // 0: no limit
  if (open.rfind("/vsigzip/", 0) == 0) {
    VSIStatBufL st;
    const std::uint64_t packed = VSIStatL(open.c_str() + 9, &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
    const std::uint64_t ratio = std::max<std::uint64_t>(1, options.gzip_max_ratio);
    max_bytes = std::max(options.gzip_min_bytes, packed > UINT64_MAX / ratio ? UINT64_MAX : packed * ratio);
  }
  // GDAL caches a .gz's unpacked size in x.gz.properties beside it: an input is not ours to write beside.
  struct NoGzipProperties {
    std::string old;
    bool had = false;
    explicit NoGzipProperties(bool on) {
      if (!on) return;
      const char* v = CPLGetThreadLocalConfigOption("CPL_VSIL_GZIP_WRITE_PROPERTIES", nullptr);
      had = v != nullptr;
      if (v) old = v;
      CPLSetThreadLocalConfigOption("CPL_VSIL_GZIP_WRITE_PROPERTIES", "NO");
      set = true;
    }
    ~NoGzipProperties() {
      if (set) CPLSetThreadLocalConfigOption("CPL_VSIL_GZIP_WRITE_PROPERTIES", had ? old.c_str() : nullptr);
    }
    bool set = false;
  } no_properties(max_bytes != 0);
  auto too_big = [&](std::uint64_t read) {
    return InputError(path + ": unpacks to more than " + std::to_string(max_bytes) + " bytes after " +
                      std::to_string(read) + " read, over " + std::to_string(options.gzip_max_ratio) +
                      " times its compressed size; stopped (gzip bomb?). If the file is genuine, gunzip it and read "
                      "the plain file");
  };
  // on_bytes counts a file's bytes on disk (the progress total): a gzip input's packed bytes, scaled
  // from the unpacked ones its reader is told (gzip_progress.h).
  const bool gzip = open.rfind("/vsigzip/", 0) == 0;
  std::optional<GzipProgress> packed;
  if (gzip && options.on_bytes) packed.emplace(open.substr(9), options.on_bytes);
  auto told_bytes = [&](std::uint64_t n) {
    if (packed) packed->unpacked(n);
    else if (options.on_bytes) options.on_bytes(n);
  };
  if (info.format == InputFormat::CityGml) {
    CityGmlOptions opt;
    opt.lod = options.lod;
    opt.dom_max_bytes = citygml::in_memory_bytes();
    std::uint64_t unpacked = 0;
    if (max_bytes || options.on_bytes)
      opt.on_bytes = [&](std::uint64_t n) {
        unpacked += n;
        if (max_bytes && unpacked > max_bytes) throw too_big(unpacked);
        told_bytes(n);
      };
    read_citygml(open, opt, [&](Mesh&& m) {
      ++info.meshes;
      if (info.source_srs != info.citygml.srs_name) info.source_srs = info.citygml.srs_name;
      on_mesh(std::move(m));
    }, problems, info.citygml);
    if (packed) packed->finish();
    return;
  }
  if (info.format == InputFormat::CityJson || info.format == InputFormat::CityJsonSeq) {
    ReadOptions with_bytes = options;
    with_bytes.on_bytes = options.on_bytes ? std::function<void(std::uint64_t)>(told_bytes) : nullptr;
    cityjson::read_into(open, with_bytes, max_bytes, on_mesh, problems, info);
    if (packed) packed->finish();
    return;
  }
  if (info.format == InputFormat::Ogr) {
    read_ogr(path, options.ogr, [&] {
      info.source_srs = info.ogr.source_srs;
      info.source_axis = info.ogr.east_north ? AxisOrder::EastNorth : AxisOrder::NorthEast;
    }, [&](Mesh&& m) {
      ++info.meshes;
      on_mesh(std::move(m));
    }, problems, info.ogr);
    return;
  }

  info.in_working_crs = true;
  CrsOptions crs;
  crs.target_srs = options.target_srs;
  Georeferencer geo(crs, path);
  std::optional<ModelPlacement> origin;
  if (!options.origin.empty()) origin = parse_origin(options.origin);
  auto deliver = [&](Mesh& mesh, bool ok, const std::string& reason) {
    if (!ok) {
      problems.push_back(Problem{mesh.source_id, path, "georeference", "TRANSFORM_FAILED", reason});
      return;
    }
    ++info.meshes;
    on_mesh(std::move(mesh));
  };
  auto finish = [&] {
    if (geo.decided() && geo.working_crs().known) info.working_crs = geo.working_crs();
    info.notes = geo.notes();
  };
  const std::string no_origin = ": has no georeference (no KML Location, no CESIUM_RTC, no ECEF transform): pass "
                                "--origin lon,lat,alt (degrees, degrees, metres) to place its local frame";
  // glTF and 3D Tiles: ECEF meshes placed by PROJ, local ones at --origin.
  auto place_gltf = [&](Mesh&& mesh, GltfFrame frame) {
    std::string reason;
    bool ok = false;
    if (frame == GltfFrame::Ecef) {
      ok = geo.place_ecef(mesh, &reason);
    } else {
      if (!origin) throw InputError(path + no_origin);
      ok = geo.place_local(mesh, *origin, &reason);
    }
    deliver(mesh, ok, reason);
  };

  switch (info.format) {
    case InputFormat::Kml:
    case InputFormat::Kmz:
      try {
        read_kml(open, options.kml, [&](Mesh&& mesh, const ModelPlacement& pl) {
          std::string reason;
          const bool ok = geo.place_local(mesh, pl, &reason);
          deliver(mesh, ok, reason);
        }, problems, info.kml);
      } catch (...) {
        finish();
        throw;
      }
      break;
    case InputFormat::Collada: {
      if (!origin) throw InputError(path + no_origin);
      ColladaOptions copt = options.kml.collada;
      copt.max_bytes = options.kml.max_entry_bytes;
      ColladaInfo cinfo;
      Mesh mesh = read_collada(path, path, copt, problems, cinfo);
      if (!mesh.faces.empty()) {
        std::string reason;
        const bool ok = geo.place_local(mesh, *origin, &reason);
        deliver(mesh, ok, reason);
      }
      break;
    }
    case InputFormat::Gltf:
    case InputFormat::Glb:
      try {
        read_gltf(path, options.gltf, place_gltf, problems, info.gltf);
      } catch (...) {
        finish();
        throw;
      }
      break;
    case InputFormat::Tiles3d:
      try {
        Tiles3dOptions topt = options.tiles3d;
        topt.gltf = options.gltf;
        // The level of detail by geometric error: a --config option, so that the CLI, the driver and Python have it.
        if (const char* e = CPLGetConfigOption("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR", nullptr)) {
          char* end = nullptr;
          const double v = std::strtod(e, &end);
          if (end == e || *end != '\0' || !(v >= 0))
            throw InvalidArgument(std::string("GROUNDPLAN_3DTILES_GEOMETRIC_ERROR=") + e + ": not a number of metres >= 0");
          topt.geometric_error = v;
        }
        // Progress over tiles: the tileset file's bytes told in shares, one a content.
        VSIStatBufL st;
        const std::uint64_t size = VSIStatL(path.c_str(), &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
        std::uint64_t told = 0;
        auto progress = [&](std::size_t done, std::size_t total) {
          const std::uint64_t now = total ? size * done / total : size;
          if (options.on_bytes && now > told) options.on_bytes(now - told);
          told = now;
        };
        read_3d_tiles(path, topt, place_gltf, problems, info.tiles3d, progress);
        if (options.on_bytes && size > told) options.on_bytes(size - told);
      } catch (...) {
        finish();
        throw;
      }
      break;
    default:
      break;
  }
  finish();
}

}  // namespace groundplan::gis
