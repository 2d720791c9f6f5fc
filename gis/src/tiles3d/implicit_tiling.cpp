// SPDX-License-Identifier: MIT
// 3D Tiles implicit tiling (implicit_tiling.h): subtree files (binary "subt" or JSON), availability by
// constant or bitstream, tiles in Morton order within each level of a subtree.
#include "tiles3d/implicit_tiling.h"

#include <groundplan/error.h>

#include <cstring>
#include <memory>

namespace groundplan::gis::tiles3d {
namespace {

constexpr int kMaxLevels = 31;  // x, y, z below 2^31; deeper is no city

/// One availability: a constant or a bitstream of at least `bits` bits (little-endian bit order in bytes).
struct Availability {
  bool constant = true, value = false;
  std::string bytes;
  bool get(std::uint64_t i) const {
    if (constant) return value;
    return i / 8 < bytes.size() && ((static_cast<unsigned char>(bytes[i / 8]) >> (i % 8)) & 1);
  }
};

struct Subtree {
  std::string file;
  Availability tiles, content, children;
};

std::uint64_t level_offset(bool octree, int level) {  // tiles in the levels above `level` of a subtree
  const std::uint64_t b = octree ? 8 : 4;
  std::uint64_t n = 0, p = 1;
  for (int l = 0; l < level; ++l) n += p, p *= b;
  return n;
}

std::uint64_t level_size(bool octree, int level) { return std::uint64_t{1} << ((octree ? 3 : 2) * level); }

class Walker {
 public:
  Walker(const ImplicitTiling& t, const std::string& tileset, const LoadFile& load,
         const std::function<bool(const ImplicitTile&)>& visit, std::vector<std::pair<std::string, std::string>>& problems)
      : t_(t), tileset_(tileset), load_(load), visit_(visit), problems_(problems) {}

  /// The subtree whose root is `root` (its uri template, like the contents', is relative to the tileset).
  void subtree(const ImplicitTile& root) {
    std::unique_ptr<Subtree> s;
    std::string path;
    try {
      s = read_subtree(tileset_, expand(t_.subtrees, root), path);
    } catch (const InputError& e) {
      problems_.emplace_back(path.empty() ? tileset_ : path, e.what());
      return;
    }
    tile(*s, 0, 0, root);
  }

 private:
  const unsigned char* u8(const std::string& b, std::size_t at) const {
    return reinterpret_cast<const unsigned char*>(b.data()) + at;
  }

  /// An availability object of the subtree JSON, its bitstream at least `bits` long.
  Availability availability(const nlohmann::json& a, const std::vector<std::string>& views, std::uint64_t bits,
                            const std::string& path, const char* what) const {
    Availability out;
    if (!a.is_object()) throw InputError(path + ": its " + std::string(what) + " is not an object");
    if (a.contains("constant") && a["constant"].is_number_integer()) {
      out.value = a["constant"].get<int>() != 0;
      return out;
    }
    const char* key = a.contains("bitstream") ? "bitstream" : "bufferView";  // "bufferView": before 1.1
    if (!a.contains(key) || !a[key].is_number_unsigned() || a[key].get<std::uint64_t>() >= views.size())
      throw InputError(path + ": its " + std::string(what) + " has neither a constant nor a bitstream in range");
    out.constant = false;
    out.bytes = views[a[key].get<std::size_t>()];
    if (out.bytes.size() < (bits + 7) / 8)
      throw InputError(path + ": its " + std::string(what) + " bitstream has " + std::to_string(out.bytes.size()) +
                       " bytes, " + std::to_string((bits + 7) / 8) + " are needed for " + std::to_string(bits) +
                       " tiles (a short bitstream)");
    return out;
  }

  std::unique_ptr<Subtree> read_subtree(const std::string& from, const std::string& uri, std::string& path) const {
    const std::string b = load_(from, uri, path);
    auto s = std::make_unique<Subtree>();
    s->file = path;
    nlohmann::json j;
    std::string binary;
    if (b.size() >= 4 && std::memcmp(b.data(), "subt", 4) == 0) {
      if (b.size() < 24) throw InputError(path + ": truncated subtree: its header alone takes 24 bytes");
      std::uint64_t jl, bl;
      std::memcpy(&jl, b.data() + 8, 8);
      std::memcpy(&bl, b.data() + 16, 8);
      if (jl > b.size() - 24 || bl > b.size() - 24 - jl)
        throw InputError(path + ": its subtree header says " + std::to_string(jl) + " + " + std::to_string(bl) +
                         " bytes, the file has " + std::to_string(b.size() - 24) + " after its header");
      try {
        j = nlohmann::json::parse(b.begin() + 24, b.begin() + 24 + static_cast<std::ptrdiff_t>(jl));
      } catch (const std::exception& e) {
        throw InputError(path + ": its subtree JSON cannot be parsed: " + e.what());
      }
      binary = b.substr(static_cast<std::size_t>(24 + jl), static_cast<std::size_t>(bl));
    } else {
      try {
        j = nlohmann::json::parse(b);
      } catch (const std::exception& e) {
        throw InputError(path + ": not a subtree (neither \"subt\" nor JSON): " + e.what());
      }
    }
    if (!j.is_object()) throw InputError(path + ": its subtree JSON is not an object");
    std::vector<std::string> buffers, views;
    if (j.contains("buffers") && j["buffers"].is_array())
      for (const auto& buf : j["buffers"]) {
        if (buf.contains("uri") && buf["uri"].is_string()) {
          std::string bpath;
          buffers.push_back(load_(path, buf["uri"].get<std::string>(), bpath));
        } else {
          buffers.push_back(binary);
        }
      }
    if (j.contains("bufferViews") && j["bufferViews"].is_array())
      for (const auto& v : j["bufferViews"]) {
        const std::uint64_t bi = v.value("buffer", std::uint64_t{0}), off = v.value("byteOffset", std::uint64_t{0}),
                            len = v.value("byteLength", std::uint64_t{0});
        if (bi >= buffers.size() || off > buffers[bi].size() || len > buffers[bi].size() - off)
          throw InputError(path + ": a subtree bufferView reaches past its buffer");
        views.push_back(buffers[bi].substr(static_cast<std::size_t>(off), static_cast<std::size_t>(len)));
      }
    const std::uint64_t tiles = level_offset(t_.octree, t_.subtree_levels);
    s->tiles = availability(j.value("tileAvailability", nlohmann::json()), views, tiles, path, "tileAvailability");
    if (j.contains("contentAvailability") && j["contentAvailability"].is_array() && !j["contentAvailability"].empty())
      s->content = availability(j["contentAvailability"][0], views, tiles, path, "contentAvailability");
    s->children = availability(j.value("childSubtreeAvailability", nlohmann::json()), views,
                               level_size(t_.octree, t_.subtree_levels), path, "childSubtreeAvailability");
    return s;
  }

  void tile(const Subtree& s, int l, std::uint64_t m, const ImplicitTile& here_in) {
    const std::uint64_t b = t_.octree ? 8 : 4;
    const std::uint64_t index = level_offset(t_.octree, l) + m;
    if (!s.tiles.get(index)) return;
    ImplicitTile here = here_in;
    here.has_content = !t_.content.empty() && s.content.get(index);
    here.has_children = false;
    if (here.level + 1 < t_.available_levels)
      for (std::uint64_t c = 0; c < b && !here.has_children; ++c)
        here.has_children = l + 1 < t_.subtree_levels ? s.tiles.get(level_offset(t_.octree, l + 1) + m * b + c)
                                                       : s.children.get(m * b + c);
    if (!visit_(here) || !here.has_children) return;
    for (std::uint64_t c = 0; c < b; ++c) {
      ImplicitTile child;
      child.level = here.level + 1;
      child.x = 2 * here.x + (c & 1), child.y = 2 * here.y + ((c >> 1) & 1), child.z = 2 * here.z + ((c >> 2) & 1);
      if (l + 1 < t_.subtree_levels) tile(s, l + 1, m * b + c, child);
      else if (s.children.get(m * b + c)) subtree(child);
    }
  }

  const ImplicitTiling& t_;
  const std::string& tileset_;
  const LoadFile& load_;
  const std::function<bool(const ImplicitTile&)>& visit_;
  std::vector<std::pair<std::string, std::string>>& problems_;
};

}  // namespace

std::string parse_implicit(const nlohmann::json& tile, ImplicitTiling& out) {
  const nlohmann::json& it = tile["implicitTiling"];
  if (!it.is_object()) return "its implicitTiling is not an object";
  const std::string scheme = it.value("subdivisionScheme", std::string());
  if (scheme != "QUADTREE" && scheme != "OCTREE") return "its subdivisionScheme \"" + scheme + "\" is neither QUADTREE nor OCTREE";
  out.octree = scheme == "OCTREE";
  if (!it.contains("subtreeLevels") || !it["subtreeLevels"].is_number_integer() || !it.contains("availableLevels") ||
      !it["availableLevels"].is_number_integer())
    return "its subtreeLevels or availableLevels is not a whole number";
  out.subtree_levels = it["subtreeLevels"].get<int>();
  out.available_levels = it["availableLevels"].get<int>();
  // A subtree's bitstreams hold (B^levels - 1) / (B - 1) bits: 10 octree levels are already 1.2e9 tiles.
  const int max_subtree = out.octree ? 10 : 15;
  if (out.subtree_levels < 1 || out.subtree_levels > max_subtree || out.available_levels < 1 ||
      out.available_levels > kMaxLevels)
    return "its subtreeLevels " + std::to_string(out.subtree_levels) + " or availableLevels " +
           std::to_string(out.available_levels) + " is out of range (1-" + std::to_string(max_subtree) + ", 1-" +
           std::to_string(kMaxLevels) + ")";
  if (!it.contains("subtrees") || !it["subtrees"].is_object() || !it["subtrees"].contains("uri") ||
      !it["subtrees"]["uri"].is_string())
    return "its subtrees have no uri template";
  out.subtrees = it["subtrees"]["uri"].get<std::string>();
  if (tile.contains("content") && tile["content"].is_object() && tile["content"].contains("uri") &&
      tile["content"]["uri"].is_string())
    out.content = tile["content"]["uri"].get<std::string>();
  return {};
}

std::string expand(const std::string& templ, const ImplicitTile& t) {
  std::string out;
  for (std::size_t i = 0; i < templ.size(); ++i) {
    auto at = [&](const char* key) { return templ.compare(i, std::strlen(key), key) == 0; };
    if (at("{level}")) out += std::to_string(t.level), i += 6;
    else if (at("{x}")) out += std::to_string(t.x), i += 2;
    else if (at("{y}")) out += std::to_string(t.y), i += 2;
    else if (at("{z}")) out += std::to_string(t.z), i += 2;
    else out += templ[i];
  }
  return out;
}

void walk_implicit(const ImplicitTiling& tiling, const std::string& tileset, const LoadFile& load,
                   const std::function<bool(const ImplicitTile&)>& visit,
                   std::vector<std::pair<std::string, std::string>>& problems) {
  Walker(tiling, tileset, load, visit, problems).subtree(ImplicitTile{});
}

}  // namespace groundplan::gis::tiles3d
