// SPDX-License-Identifier: MIT
// The 3D Tiles tile tree (tiles3d.h): tileset.json and its external tilesets, walked from the root with
// each tile's transform composed down to its contents, the level of detail chosen by refinement.
#include <groundplan/error.h>
#include <groundplan/gis/tiles3d.h>

#include "tiles3d/implicit_tiling.h"
#include "tiles3d/tile_content.h"
#include "xml/safe_xml.h"
#include "collada/collada_internal.h"

#include <nlohmann/json.hpp>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>
#include <unordered_map>

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;
using tiles3d::Mat4;

constexpr double kMaxTranslation = 1e8;  // metres: ~15 Earth radii; anything farther places nothing on the Earth
constexpr double kMaxLinear = 1e6;       // a rotation-scale entry: a millionfold scale is no placement
constexpr std::uint32_t kExternalRoot = 1u << 31;  // a TilePath step into an external tileset (+ the content's index)

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string percent_decoded(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

class Walker {
 public:
  Walker(const std::string& root_path, const Tiles3dOptions& opt, const GltfMeshCallback& cb,
         std::vector<Problem>& problems, Tiles3dInfo& info)
      : opt_(opt), cb_(cb), problems_(problems), info_(info) {
    vsi_ = root_path.rfind("/vsi", 0) == 0;
    const fs::path folder = fs::path(root_path).parent_path();
    std::error_code ec;
    root_folder_ = vsi_ ? folder : fs::weakly_canonical(folder.empty() ? fs::path(".") : folder, ec);
    if (ec) throw InputError(root_path + ": cannot resolve the tileset's folder: " + ec.message());
  }

  /// The root tileset: throws when it cannot be read; below it, everything is a Problem.
  void root(const std::string& path) {
    const nlohmann::json j = load_tileset(path);
    if (j.contains("asset") && j["asset"].is_object() && j["asset"].contains("version") && j["asset"]["version"].is_string())
      info_.version = j["asset"]["version"].get<std::string>();
    tileset(path, j, detail::kIdentity, "REPLACE", 0, {});
  }

  /// One content file given alone: the content of a tile without transform. Throws when it cannot be read.
  void content_alone(const std::string& path) {
    Job job{path, fs::path(path).filename().string(), detail::kIdentity, {}};
    Done done = read_job(job);
    if (!done.failure.empty()) throw InputError(done.failure);
    deliver(done);
  }

  /// The contents the walk chose, read side by side (each read, parsed and decoded on its own thread),
  /// delivered on this thread, the deepest tiles first (so that a finer level of a building comes before its
  /// coarser copies in ancestor tiles: deliver()), in tile order within a depth: at most two contents a
  /// thread in flight.
  void read_contents(const std::function<void(std::size_t done, std::size_t total)>& progress) {
    std::stable_sort(jobs_.begin(), jobs_.end(), [](const Job& a, const Job& b) { return a.path.size() > b.path.size(); });
    const std::size_t n = jobs_.size();
    std::size_t next = 0, delivered = 0;
    const auto tokens = static_cast<std::size_t>(2 * std::max(1, tbb::this_task_arena::max_concurrency()));
    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                            [&](tbb::flow_control& fc) -> std::size_t {
                                              if (next == n) fc.stop();
                                              return next < n ? next++ : n;
                                            }) &
            tbb::make_filter<std::size_t, std::shared_ptr<Done>>(
                tbb::filter_mode::parallel, [&](std::size_t k) { return std::make_shared<Done>(read_job(jobs_[k])); }) &
            tbb::make_filter<std::shared_ptr<Done>, void>(tbb::filter_mode::serial_in_order,
                                                          [&](const std::shared_ptr<Done>& done) {
                                                            if (!done->failure.empty())
                                                              problem(done->file, "UNREADABLE_TILE", done->failure);
                                                            deliver(*done);
                                                            if (progress) progress(++delivered, n);
                                                          }));
  }

  std::size_t contents() const { return jobs_.size(); }

 private:
  /// Where a tile sits in the tree: the index of each child taken from the root (an external tileset's root
  /// and an implicit tile's children are children too). A tile is an ancestor of another when its path is a
  /// proper prefix of the other's.
  using TilePath = std::vector<std::uint32_t>;
  static bool is_ancestor(const TilePath& a, const TilePath& b) {
    return a.size() < b.size() && std::equal(a.begin(), a.end(), b.begin());
  }
  struct Job {
    std::string file, label;
    Mat4 transform;
    TilePath path;
  };
  /// A content read: its meshes (placed in ECEF or local, not yet in the working CRS) and problems.
  struct Done {
    std::string file;
    TilePath path;
    std::vector<std::pair<Mesh, GltfFrame>> meshes;
    std::vector<Problem> problems;
    Tiles3dInfo info;  // contents, georeference, by_feature of this content
    std::string failure;  // the content could not be read: why (an InputError's message)
  };

  Done read_job(const Job& job) const {
    Done d;
    d.file = job.file;
    d.path = job.path;
    try {
      xml::ByteBudget budget;
      budget.max_entry_bytes = budget.max_total_bytes = opt_.gltf.max_bytes;
      const std::string bytes = xml::read_vsi_file(job.file, job.file, budget);
      tiles3d::read_content(job.file, job.label, bytes, root_folder_.string(), job.transform, opt_,
                            [&](Mesh&& m, GltfFrame f) { d.meshes.emplace_back(std::move(m), f); }, d.problems, d.info);
    } catch (const InputError& e) {
      d.failure = e.what();
    }
    return d;
  }

  void deliver(Done& d) {
    problems_.insert(problems_.end(), std::make_move_iterator(d.problems.begin()), std::make_move_iterator(d.problems.end()));
    info_.contents += d.info.contents;
    if (!d.info.georeference.empty()) info_.georeference = d.info.georeference;
    info_.by_feature = info_.by_feature || d.info.by_feature;
    for (auto& [mesh, frame] : d.meshes) {
      // A building id that an earlier content gave already. Contents come deepest first (read_contents), so
      // when that content is in a tile below this one, it holds the same building at a finer level (the
      // children of an ADD tile, or a tile below the level the walk stopped at for another branch): the finer
      // copy is the one read, as "the finest level" says, and this coarser one is left out, said in a NOTE.
      // Anywhere else (two contents of one tile, a building cut between neighbouring tiles) the two copies
      // may be different pieces of the building: both are read, and said, as CityGML's repeated gml:id is.
      std::vector<Delivered>& earlier = delivered_[mesh.source_id];
      const auto finer = std::find_if(earlier.begin(), earlier.end(), [&](const Delivered& e) { return is_ancestor(d.path, e.path); });
      if (finer != earlier.end()) {
        problems_.push_back(Problem{mesh.source_id, d.file, "read", "NOTE",
                                    "building id \"" + mesh.source_id + "\" is also in " + finer->file +
                                        ", a tile below this one (a finer level of detail): that copy is read, this "
                                        "coarser one is left out"});
        ++info_.coarser_copies_left_out;
        continue;
      }
      if (!earlier.empty() && earlier.front().delivery != deliveries_)  // (one content may repeat an id: glTF nodes)
        problems_.push_back(Problem{mesh.source_id, d.file, "read", "DUPLICATE_ID",
                                    "building id \"" + mesh.source_id + "\" is also in " + earlier.front().file +
                                        " (two contents of one tile, or a building cut between tiles): both are read"});
      if (earlier.empty() || earlier.back().delivery != deliveries_) earlier.push_back(Delivered{d.file, d.path, deliveries_});
      cb_(std::move(mesh), frame);
    }
    d.meshes.clear();
    ++deliveries_;
  }

  void problem(const std::string& file, const std::string& code, const std::string& reason) {
    problems_.push_back(Problem{"", file, "read", code, reason});
  }

  nlohmann::json load_tileset(const std::string& path) {
    xml::ByteBudget budget;
    budget.max_entry_bytes = budget.max_total_bytes = opt_.max_json_bytes;
    const std::string text = xml::read_vsi_file(path, path, budget);
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
      throw InputError(path + ": not a readable 3D Tiles tileset: its JSON cannot be parsed: " + e.what());
    }
    if (!j.is_object() || !j.contains("root") || !j["root"].is_object())
      throw InputError(path + ": not a 3D Tiles tileset: no \"root\" tile object");
    return j;
  }

  void tileset(const std::string& path, const nlohmann::json& j, const Mat4& parent, const std::string& refine, int depth,
               const TilePath& at) {
    if (j.contains("extensionsRequired") && j["extensionsRequired"].is_array())
      for (const auto& e : j["extensionsRequired"])
        if (e.is_string() && e.get<std::string>() != "3DTILES_content_gltf")
          throw InputError(path + ": requires the 3D Tiles extension " + e.get<std::string>() +
                           ", which groundplan does not read");
    stack_.push_back(key(path));
    tile(path, j["root"], parent, refine, depth, at);
    stack_.pop_back();
  }

  /// What identifies a tileset file on the stack of those being read (cycles).
  std::string key(const std::string& path) const {
    if (vsi_) return path;
    std::error_code ec;
    const fs::path c = fs::weakly_canonical(path, ec);
    return ec ? path : c.string();
  }

  /// A tile's transform (column-major in JSON) as a row-major matrix; false (and why) when it is no placement.
  static bool transform_of(const nlohmann::json& t, Mat4& m, std::string& why) {
    if (!t.is_array() || t.size() != 16) return why = "its transform is not an array of 16 numbers", false;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) {
        const auto& v = t[static_cast<std::size_t>(c * 4 + r)];
        if (!v.is_number()) return why = "its transform holds something that is not a number", false;
        m[static_cast<std::size_t>(r * 4 + c)] = v.get<double>();
      }
    for (double v : m)
      if (!std::isfinite(v)) return why = "its transform holds NaN or infinity", false;
    if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)
      return why = "its transform is not affine (its last row is not 0 0 0 1)", false;
    for (int r = 0; r < 3; ++r) {
      if (std::abs(m[static_cast<std::size_t>(r * 4 + 3)]) > kMaxTranslation)
        return why = "its transform moves by more than 1e8 m", false;
      for (int c = 0; c < 3; ++c)
        if (std::abs(m[static_cast<std::size_t>(r * 4 + c)]) > kMaxLinear)
          return why = "its transform scales by more than a million", false;
    }
    return true;
  }

  /// The file a content uri names, under the root tileset's folder; empty (and a Problem) when it names
  /// the network or leaves that folder.
  std::string resolve(const std::string& tileset_path, const std::string& raw) {
    std::string uri = raw;
    const auto cut = uri.find_first_of("?#");
    if (cut != std::string::npos) uri.erase(cut);
    std::size_t colon = uri.find(':');
    const bool scheme = colon != std::string::npos && colon > 1 &&
                        std::all_of(uri.begin(), uri.begin() + static_cast<std::ptrdiff_t>(colon), [](unsigned char c) {
                          return std::isalnum(c) || c == '+' || c == '-' || c == '.';
                        });
    if (scheme) {
      problem(tileset_path, "NETWORK_URI",
              "content uri \"" + raw.substr(0, 200) + "\" names " + lower(uri.substr(0, colon)) +
                  ": not fetched (groundplan reads local files only: download the tileset and give its tileset.json)");
      return {};
    }
    uri = percent_decoded(uri);
    const fs::path rel(uri);
    if (uri.empty() || rel.is_absolute() || uri[0] == '/' || uri[0] == '\\' || (uri.size() > 1 && uri[1] == ':')) {
      problem(tileset_path, "OUTSIDE_TILESET", "content uri \"" + raw.substr(0, 200) + "\" is empty or absolute: not read");
      return {};
    }
    const fs::path target = fs::path(tileset_path).parent_path() / rel;
    bool inside = true;
    if (vsi_) {
      inside = uri.find("..") == std::string::npos && uri.find('\\') == std::string::npos;
    } else {
      std::error_code ec;
      const fs::path t = fs::weakly_canonical(target, ec);
      auto r = root_folder_.begin();
      auto p = t.begin();
      for (; !ec && r != root_folder_.end(); ++r, ++p)
        if (p == t.end() || *r != *p) inside = false;
      if (ec) inside = false;
    }
    if (!inside) {
      problem(tileset_path, "OUTSIDE_TILESET",
              "content uri \"" + raw.substr(0, 200) + "\" leads outside the tileset's folder " + root_folder_.string() +
                  ": not read");
      return {};
    }
    return target.lexically_normal().string();
  }

  void tile(const std::string& tileset_path, const nlohmann::json& t, const Mat4& parent, const std::string& parent_refine,
            int depth, const TilePath& at) {
    if (!t.is_object()) return problem(tileset_path, "BAD_TILE", "a tile is not a JSON object: skipped");
    if (depth > opt_.max_depth)
      return problem(tileset_path, "TILE_TOO_DEEP",
                     "tiles nested deeper than " + std::to_string(opt_.max_depth) + " levels: not read");
    if (++info_.tiles > opt_.max_tiles) {
      if (info_.tiles == opt_.max_tiles + 1)
        problem(tileset_path, "TOO_MANY_TILES", "more than " + std::to_string(opt_.max_tiles) + " tiles: the rest is not read");
      return;
    }
    Mat4 world = parent;
    if (t.contains("transform")) {
      Mat4 local;
      std::string why;
      if (!transform_of(t["transform"], local, why))
        return problem(tileset_path, "BAD_TRANSFORM", "a tile at depth " + std::to_string(depth) + " is skipped with its children: " + why);
      world = detail::multiply(parent, local);
    }
    std::string refine = parent_refine;
    if (t.contains("refine") && t["refine"].is_string()) {
      const std::string r = lower(t["refine"].get<std::string>());
      if (r == "add" || r == "replace") refine = r == "add" ? "ADD" : "REPLACE";
    }
    if (t.contains("implicitTiling")) return implicit(tileset_path, t, world, refine, at);
    const bool has_children = t.contains("children") && t["children"].is_array() && !t["children"].empty();
    const double error = t.contains("geometricError") && t["geometricError"].is_number() ? t["geometricError"].get<double>() : 0;
    const bool stop = !has_children || (opt_.geometric_error >= 0 && error <= opt_.geometric_error);
    const bool take = stop || refine == "ADD";
    std::vector<const nlohmann::json*> contents;
    if (t.contains("content") && t["content"].is_object()) contents.push_back(&t["content"]);
    if (t.contains("contents") && t["contents"].is_array())
      for (const auto& c : t["contents"])
        if (c.is_object()) contents.push_back(&c);
    for (std::uint32_t k = 0; k < contents.size(); ++k) {
      const nlohmann::json* c = contents[k];
      const nlohmann::json* u = c->contains("uri") ? &(*c)["uri"] : c->contains("url") ? &(*c)["url"] : nullptr;
      if (!u || !u->is_string()) {
        problem(tileset_path, "BAD_TILE", "a tile content has no uri: skipped");
        continue;
      }
      const std::string uri = u->get<std::string>();
      const std::string file = resolve(tileset_path, uri);
      if (file.empty()) continue;
      if (lower(fs::path(file).extension().string()) == ".json") {
        TilePath below = at;  // the external tileset's root: a child of this tile, after its children
        below.push_back(kExternalRoot + k);
        external(tileset_path, file, world, refine, depth, below);
        continue;
      }
      if (!take) {
        ++info_.skipped_by_level;
        continue;
      }
      jobs_.push_back(Job{file, uri, world, at});
    }
    if (stop) return;
    TilePath below = at;
    below.push_back(0);
    for (const auto& child : t["children"]) {
      tile(tileset_path, child, world, refine, depth + 1, below);
      ++below.back();
    }
  }

  /// A tile with implicit tiling: its available descendants (subtree files) chosen as explicit tiles are.
  void implicit(const std::string& tileset_path, const nlohmann::json& t, const Mat4& world, const std::string& refine,
                const TilePath& at) {
    tiles3d::ImplicitTiling tiling;
    const std::string why = tiles3d::parse_implicit(t, tiling);
    if (!why.empty()) return problem(tileset_path, "BAD_TILE", "a tile with implicit tiling is skipped: " + why);
    const double root_error = t.contains("geometricError") && t["geometricError"].is_number() ? t["geometricError"].get<double>() : 0;
    auto load = [&](const std::string& from, const std::string& uri, std::string& path) {
      path = resolve(from, uri);  // a uri outside the tileset or on the network: a problem there, and not read
      if (path.empty()) throw InputError(from + ": subtree file \"" + uri.substr(0, 200) + "\" is not read");
      xml::ByteBudget budget;
      budget.max_entry_bytes = budget.max_total_bytes = opt_.max_json_bytes;
      return xml::read_vsi_file(path, path, budget);
    };
    auto visit = [&](const tiles3d::ImplicitTile& it) {
      if (it.level > 0 && ++info_.tiles > opt_.max_tiles) {  // level 0 is the explicit tile, counted already
        if (info_.tiles == opt_.max_tiles + 1)
          problem(tileset_path, "TOO_MANY_TILES", "more than " + std::to_string(opt_.max_tiles) + " tiles: the rest is not read");
        return false;
      }
      const double error = root_error / std::ldexp(1.0, it.level);  // halved at each level
      const bool stop = !it.has_children || (opt_.geometric_error >= 0 && error <= opt_.geometric_error);
      if (it.has_content) {
        if (stop || refine == "ADD") {
          const std::string uri = tiles3d::expand(tiling.content, it);
          const std::string file = resolve(tileset_path, uri);
          if (!file.empty()) jobs_.push_back(Job{file, uri, world, implicit_path(at, it)});
        } else {
          ++info_.skipped_by_level;
        }
      }
      return !stop;
    };
    std::vector<std::pair<std::string, std::string>> failed;
    tiles3d::walk_implicit(tiling, tileset_path, load, visit, failed);
    for (const auto& [file, what] : failed) problem(file, "UNREADABLE_SUBTREE", what + ": the tiles below it are left out");
  }

  /// An implicit tile's path: the explicit tile's, then the child taken at each level (the bits of x, y, z).
  static TilePath implicit_path(const TilePath& at, const tiles3d::ImplicitTile& it) {
    TilePath p = at;
    for (int l = it.level - 1; l >= 0; --l)
      p.push_back(static_cast<std::uint32_t>(((it.x >> l) & 1u) | (((it.y >> l) & 1u) << 1) | (((it.z >> l) & 1u) << 2)));
    return p;
  }

  void external(const std::string& from, const std::string& file, const Mat4& world, const std::string& refine, int depth,
                const TilePath& at) {
    const std::string k = key(file);
    if (std::find(stack_.begin(), stack_.end(), k) != stack_.end())
      return problem(from, "TILESET_CYCLE", "external tileset " + file + " includes itself (through " + from + "): not followed");
    try {
      const nlohmann::json j = load_tileset(file);
      ++info_.external_tilesets;
      tileset(file, j, world, refine, depth + 1, at);
    } catch (const InputError& e) {
      problem(file, "UNREADABLE_TILE", e.what());
    }
  }

  const Tiles3dOptions& opt_;
  const GltfMeshCallback& cb_;
  std::vector<Problem>& problems_;
  Tiles3dInfo& info_;
  fs::path root_folder_;
  bool vsi_ = false;
  std::vector<std::string> stack_;  // tilesets being read, root first
  std::vector<Job> jobs_;           // the contents chosen, in tile order
  struct Delivered {
    std::string file;
    TilePath path;
    std::size_t delivery;  // which content delivered (deliveries_ then)
  };
  std::size_t deliveries_ = 0;
  std::unordered_map<std::string, std::vector<Delivered>> delivered_;  // building id -> the contents that gave it
};

}  // namespace

bool looks_like_tileset(std::string_view head) {
  const auto first = head.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  return first != std::string_view::npos && head[first] == '{' && head.find("\"asset\"") != std::string_view::npos &&
         head.find("\"root\"") != std::string_view::npos;
}

void read_3d_tiles(const std::string& path, const Tiles3dOptions& options, const GltfMeshCallback& on_mesh,
                   std::vector<Problem>& problems, Tiles3dInfo& info,
                   const std::function<void(std::size_t done, std::size_t total)>& progress) {
  info = Tiles3dInfo{};
  Walker w(path, options, on_mesh, problems, info);
  const std::string ext = lower(fs::path(path).extension().string());
  if (ext == ".b3dm" || ext == ".cmpt" || ext == ".i3dm" || ext == ".pnts") {
    w.content_alone(path);
    return;
  }
  w.root(path);
  w.read_contents(progress);
}

}  // namespace groundplan::gis
