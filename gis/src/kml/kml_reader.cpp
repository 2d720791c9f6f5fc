// SPDX-License-Identifier: MIT
// KML / KMZ reader (issue 6). expat through xml::SafeParser; a small element stack tells Model
// Location/longitude from LookAt/longitude (the Macky sample has both). Models are handled as
// their </Model> closes (streaming: a KML of thousands of placemarks keeps one model in memory,
// plus a small cache of parsed COLLADA files that several placemarks share).
#include <groundplan/error.h>
#include <groundplan/gis/kml.h>

#include "collada/collada_internal.h"
#include "xml/safe_xml.h"

#include <cpl_string.h>
#include <cpl_vsi.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <list>
#include <optional>
#include <set>

namespace groundplan::gis {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool ends_with_ci(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() && lower(s.substr(s.size() - suffix.size())) == suffix;
}

bool kml_namespace(std::string_view uri) {
  return uri.empty() || uri == "http://www.opengis.net/kml/2.2" || uri.starts_with("http://earth.google.com/kml/") ||
         uri == "http://www.google.com/kml/ext/2.2";
}

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

bool to_double(const std::string& text, double& v) {
  std::string_view s(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size() && std::isfinite(v);
}

bool is_zip_magic(const std::string& path) {
  VSILFILE* f = VSIFOpenL(path.c_str(), "rb");
  if (!f) return false;
  unsigned char m[4] = {0, 0, 0, 0};
  const std::size_t n = VSIFReadL(m, 1, 4, f);
  VSIFCloseL(f);
  return n == 4 && m[0] == 'P' && m[1] == 'K' && m[2] == 3 && m[3] == 4;
}

bool vsi_exists(const std::string& path) {
  VSIStatBufL st;
  return VSIStatExL(path.c_str(), &st, VSI_STAT_EXISTS_FLAG | VSI_STAT_NATURE_FLAG) == 0 && !VSI_ISDIR(st.st_mode);
}

/// The .kml inside a KMZ: doc.kml at the root, else the first root-level .kml, else the first
/// .kml anywhere; names that would leave the archive are never chosen.
std::string pick_kml_entry(const std::string& archive, const std::string& display) {
  char** list = VSIReadDirRecursive(archive.c_str());
  if (!list)
    throw InputError(display + ": not a readable zip archive (KMZ), or it is empty");
  std::vector<std::string> kmls;
  for (char** e = list; *e; ++e) {
    std::string name(*e);
    std::string normal;
    if (!ends_with_ci(name, ".kml") || resolve_href(name, "", normal) != HrefStatus::Ok || normal != name) continue;
    kmls.push_back(name);
  }
  CSLDestroy(list);
  if (kmls.empty()) throw InputError(display + ": the KMZ holds no .kml file (doc.kml) at a safe path");
  for (const std::string& k : kmls)
    if (lower(k) == "doc.kml") return k;
  for (const std::string& k : kmls)
    if (k.find('/') == std::string::npos) return k;
  return kmls.front();
}

struct Model {
  std::string id;
  std::optional<double> lon, lat;
  ModelPlacement placement;
  std::string href;
  std::string bad_value;  // first unparseable number, for the Problem
};

class Reader final : public xml::Handler {
 public:
  Reader(const std::string& path, const KmlOptions& options, const KmlModelCallback& cb,
         std::vector<Problem>& problems, KmlInfo& info)
      : path_(path), opt_(options), cb_(cb), problems_(problems), info_(info) {
    budget_.max_entry_bytes = options.max_entry_bytes;
    budget_.max_total_bytes = options.max_total_bytes;
  }

  void run() {
    info_.file = path_;
    info_.kmz = ends_with_ci(path_, ".kmz") || is_zip_magic(path_);
    if (ends_with_ci(path_, ".kmz") && !is_zip_magic(path_)) {
      if (!vsi_exists(path_)) throw InputError(path_ + ": cannot open the file (does it exist and is it readable?)");
      throw InputError(path_ + ": named .kmz but not a zip archive (a KMZ is a zip holding doc.kml)");
    }
    std::string kml_display;
    if (info_.kmz) {
      archive_ = "/vsizip/" + path_;
      const std::string entry = pick_kml_entry(archive_, path_);
      const auto slash = entry.rfind('/');
      base_dir_ = slash == std::string::npos ? std::string() : entry.substr(0, slash + 1);
      info_.kml_path = archive_ + "/" + entry;
      kml_display = path_ + ":" + entry;
    } else {
      info_.kml_path = path_;
      kml_display = path_;
      // x.kml.gz is read as /vsigzip/x.kml.gz; its models and links are plain files beside it.
      const bool gz = path_.rfind("/vsigzip/", 0) == 0;
      root_dir_ = fs::path(gz ? path_.substr(9) : path_).parent_path().string();
      if (root_dir_.empty()) root_dir_ = ".";
    }
    visited_.insert(info_.kmz ? info_.kml_path.substr(archive_.size() + 1) : fs::path(path_).filename().string());
    parse_one(info_.kml_path, kml_display);
    // NetworkLinks, breadth first: each linked .kml once, hrefs relative to it (issue 16).
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      const Link link = pending_[i];
      const auto slash = link.rel.rfind('/');
      base_dir_ = slash == std::string::npos ? std::string() : link.rel.substr(0, slash + 1);
      depth_ = link.depth;
      ++info_.linked_files;
      const std::string target = info_.kmz ? archive_ + "/" + link.rel : (fs::path(root_dir_) / link.rel).string();
      const std::string display = info_.kmz ? path_ + ":" + link.rel : target;
      try {
        parse_one(target, display);
      } catch (const InputError& e) {
        // A broken tile is that tile's problem; the others are still read (a byte budget overrun is not).
        if (budget_.used > budget_.max_total_bytes) throw;
        reset_after_error();
        problem("", "BAD_NETWORK_LINK_TARGET", std::string(e.what()) + " (linked from " + link.from + ")");
      }
    }
    info_.bytes = budget_.used;
  }

  void parse_one(const std::string& target, const std::string& display) {
    saw_kml_root_ = false;
    xml::SafeParser parser(display, *this, opt_.max_xml_depth);
    xml_ = &parser;
    xml::parse_vsi_file(target, display, parser, budget_);
    xml_ = nullptr;
    if (!saw_kml_root_) throw InputError(display + ": no <kml> root element: not a KML document");
  }

  void reset_after_error() {
    xml_ = nullptr;
    stack_.clear();
    capturing_ = false;
    in_placemark_ = in_model_ = in_network_link_ = 0;
  }

  void start(std::string_view uri, std::string_view local, const char** atts) override {
    const bool kml = kml_namespace(uri);
    const std::string parent = stack_.empty() ? std::string() : stack_.back();
    stack_.push_back(kml ? std::string(local) : std::string("\x01"));  // foreign elements match nothing
    if (!kml) return;
    if (stack_.size() == 1) {
      if (local != "kml") throw InputError(xml_->name() + ": the root element is <" + std::string(local) + ">, not <kml>");
      saw_kml_root_ = true;
      return;
    }
    if (local == "Placemark") {
      ++info_.placemarks;
      ++placemark_no_;
      in_placemark_ = stack_.size();
      pm_id_ = attr(atts, "id");
      pm_name_.clear();
      pm_models_ = 0;
    } else if (local == "NetworkLink") {
      ++info_.network_links;
      in_network_link_ = stack_.size();
      nl_href_.clear();
      nl_id_ = attr(atts, "id");
    } else if (local == "Model" && in_placemark_) {
      ++info_.models;
      in_model_ = stack_.size();
      model_ = Model{};
      model_.id = attr(atts, "id");
    } else if (in_model_ && leaf_of_model(parent, local)) {
      capture();
    } else if (in_placemark_ && !in_model_ && local == "name" && stack_.size() == in_placemark_ + 1) {
      capture();
    } else if (in_network_link_ && local == "href" && (parent == "Link" || parent == "Url")) {
      capture();
    }
  }

  void end(std::string_view uri, std::string_view local) override {
    const std::string el = std::move(stack_.back());
    stack_.pop_back();
    const std::string parent = stack_.empty() ? std::string() : stack_.back();
    if (capturing_ && capture_depth_ == stack_.size() + 1) {
      const std::string v = trim(text_);
      capturing_ = false;
      xml_->capture_text(false);
      if (in_model_) set_model_value(parent, el, v);
      else if (in_network_link_ && el == "href") nl_href_ = v;
      else if (el == "name") pm_name_ = v;
    }
    if (el == "Model" && in_model_ == stack_.size() + 1) {
      in_model_ = 0;
      handle_model();
    } else if (el == "Placemark" && in_placemark_ == stack_.size() + 1) {
      in_placemark_ = 0;
    } else if (el == "NetworkLink" && in_network_link_ == stack_.size() + 1) {
      in_network_link_ = 0;
      handle_network_link();
    }
    (void)uri;
    (void)local;
  }

  void text(std::string_view chunk) override {
    if (text_.size() + chunk.size() > 1 << 20) {
      xml_->stop("a KML value longer than 1 MiB; refused as hostile or broken");
      return;
    }
    text_.append(chunk);
  }

 private:
  static std::string attr(const char** atts, std::string_view name) {
    const char* v = xml::attribute(atts, name);
    return v ? v : "";
  }

  bool leaf_of_model(const std::string& parent, std::string_view local) const {
    if (parent == "Location") return local == "longitude" || local == "latitude" || local == "altitude";
    if (parent == "Orientation") return local == "heading" || local == "tilt" || local == "roll";
    if (parent == "Scale") return local == "x" || local == "y" || local == "z";
    if (parent == "Link" || parent == "Url") return local == "href";
    if (parent == "Model") return local == "altitudeMode";
    return false;
  }

  void capture() {
    capturing_ = true;
    capture_depth_ = stack_.size();
    text_.clear();
    xml_->capture_text(true);
  }

  void set_model_value(const std::string& parent, const std::string& el, const std::string& v) {
    if (el == "href") {
      model_.href = v;
      return;
    }
    if (el == "altitudeMode") {
      if (v == "absolute") model_.placement.altitude_mode = AltitudeMode::Absolute;
      else if (v == "relativeToGround" || v == "relativeToSeaFloor") model_.placement.altitude_mode = AltitudeMode::RelativeToGround;
      else model_.placement.altitude_mode = AltitudeMode::ClampToGround;  // clampToGround, clampToSeaFloor, unknown
      return;
    }
    double d = 0;
    if (!to_double(v, d)) {
      if (model_.bad_value.empty()) model_.bad_value = parent + "/" + el + " = \"" + v + "\"";
      return;
    }
    ModelPlacement& p = model_.placement;
    if (parent == "Location") {
      if (el == "longitude") model_.lon = d;
      else if (el == "latitude") model_.lat = d;
      else p.alt_m = d;
    } else if (parent == "Orientation") {
      (el == "heading" ? p.heading_deg : el == "tilt" ? p.tilt_deg : p.roll_deg) = d;
    } else if (parent == "Scale") {
      (el == "x" ? p.scale_x : el == "y" ? p.scale_y : p.scale_z) = d;
    }
  }

  /// Placemark id, else the Model's own id, else the Placemark name, else "placemark N"; a
  /// Placemark with several models (MultiGeometry) adds "/model K" unless the Model's id names it.
  std::string source_id() const {
    if (pm_id_.empty() && !model_.id.empty()) return model_.id;
    std::string id = !pm_id_.empty() ? pm_id_ : !pm_name_.empty() ? pm_name_ : "placemark " + std::to_string(placemark_no_);
    if (pm_models_ > 1) id += "/model " + std::to_string(pm_models_);
    return id;
  }

  void problem(const std::string& id, const std::string& code, const std::string& reason) {
    problems_.push_back(Problem{id, path_, "read", code, reason});
  }

  /// A NetworkLink as a viewer follows it, within the input (issue 16). Its problems name no
  /// building (source_id empty): a link is not a building, and the pipeline counts buildings by id.
  void handle_network_link() {
    const std::string where = xml_->name() + (nl_id_.empty() ? "" : " (NetworkLink id \"" + nl_id_.substr(0, 200) + "\")");
    const std::string quoted = "NetworkLink href \"" + nl_href_.substr(0, 300) + "\" in " + where;
    std::string rel;
    switch (resolve_href(nl_href_, base_dir_, rel)) {
      case HrefStatus::Ok: break;
      case HrefStatus::Empty: problem("", "NETWORK_LINK_NOT_FOLLOWED", "a NetworkLink without href in " + where); return;
      case HrefStatus::Remote:
        problem("", "NETWORK_LINK_NOT_FOLLOWED", quoted + " is a URL: remote files are never fetched");
        return;
      case HrefStatus::Absolute:
        problem("", "LINK_OUTSIDE_INPUT", quoted + " is an absolute path: only paths relative to the KML are followed");
        return;
      case HrefStatus::Escapes:
        problem("", "LINK_OUTSIDE_INPUT", quoted + " climbs out of the " +
                                              std::string(info_.kmz ? "archive" : "input's folder") + ": not followed");
        return;
      case HrefStatus::Invalid: problem("", "BAD_LINK", quoted + " holds control characters: not followed"); return;
    }
    if (!ends_with_ci(rel, ".kml")) {
      problem("", "NETWORK_LINK_NOT_FOLLOWED", quoted + ": only links to .kml files in the same folder tree or archive "
                                                        "are followed; list other files as inputs");
      return;
    }
    if (depth_ + 1 > opt_.max_network_link_depth) {
      problem("", "NETWORK_LINK_TOO_DEEP", quoted + ": NetworkLinks nested deeper than " +
                                               std::to_string(opt_.max_network_link_depth) + " are not followed");
      return;
    }
    if (!visited_.insert(rel).second) {
      problem("", "NETWORK_LINK_REPEATED", quoted + ": " + rel +
                                               " is already read (a cycle, or a second link to it): read once");
      return;
    }
    if (pending_.size() >= opt_.max_linked_files) {
      problem("", "NETWORK_LINK_LIMIT", quoted + ": more than " + std::to_string(opt_.max_linked_files) +
                                            " linked files; not followed");
      return;
    }
    if (!info_.kmz) {
      const std::string target = (fs::path(root_dir_) / rel).string();
      if (!inside_root_on_disk(target)) {
        problem("", "LINK_OUTSIDE_INPUT", quoted + " resolves (through a symbolic link) outside the input's folder: not followed");
        return;
      }
      if (!vsi_exists(target)) {
        problem("", "LINK_TARGET_NOT_FOUND", quoted + ": link target not found (looked for " + target + ")");
        return;
      }
    } else if (!vsi_exists(archive_ + "/" + rel)) {
      problem("", "LINK_TARGET_NOT_FOUND", quoted + ": link target not found in the archive (" + rel + ")");
      return;
    }
    pending_.push_back(Link{rel, depth_ + 1, xml_->name()});
  }

  void handle_model() {
    ++pm_models_;
    const std::string id = source_id();
    if (!model_.bad_value.empty()) {
      problem(id, "BAD_MODEL_PARAMETER", "the Model's " + model_.bad_value + " is not a number: model skipped");
      return;
    }
    if (!model_.lon || !model_.lat) {
      problem(id, "NO_LOCATION", "the Model has no Location longitude/latitude: it cannot be placed");
      return;
    }
    model_.placement.lon_deg = *model_.lon;
    model_.placement.lat_deg = *model_.lat;
    if (std::fabs(*model_.lon) > 180 || std::fabs(*model_.lat) > 90) {
      problem(id, "BAD_LOCATION", "the Model's Location (" + std::to_string(*model_.lon) + ", " +
                                      std::to_string(*model_.lat) + ") is not a longitude/latitude");
      return;
    }
    std::string rel;
    const HrefStatus st = resolve_href(model_.href, base_dir_, rel);
    const std::string quoted = "Link href \"" + model_.href + "\"";
    switch (st) {
      case HrefStatus::Ok: break;
      case HrefStatus::Empty: problem(id, "NO_LINK", "the Model has no Link href to a COLLADA file"); return;
      case HrefStatus::Remote:
        problem(id, "REMOTE_LINK_NOT_FETCHED", quoted + " is a URL: remote files are never fetched");
        return;
      case HrefStatus::Absolute:
        problem(id, "LINK_OUTSIDE_INPUT", quoted + " is an absolute path: only paths relative to the KML are followed");
        return;
      case HrefStatus::Escapes:
        problem(id, "LINK_OUTSIDE_INPUT", quoted + " climbs out of the " + std::string(info_.kmz ? "archive" : "KML's folder") +
                                              ": not followed");
        return;
      case HrefStatus::Invalid: problem(id, "BAD_LINK", quoted + " holds control characters: not followed"); return;
    }
    std::string target, display;
    if (info_.kmz) {
      target = archive_ + "/" + rel;
      display = path_ + ":" + rel;
    } else {
      target = (fs::path(root_dir_) / rel).string();
      display = target;
      if (!inside_root_on_disk(target)) {
        problem(id, "LINK_OUTSIDE_INPUT", quoted + " resolves (through a symbolic link) outside the KML's folder: not followed");
        return;
      }
    }
    if (!vsi_exists(target)) {
      problem(id, "LINK_TARGET_NOT_FOUND", "link target not found: " + quoted + " (looked for " + display + ")");
      return;
    }
    const Mesh* local = load(target, display, id);
    if (!local) return;
    Mesh mesh = *local;
    mesh.source_id = id;
    mesh.name = pm_name_;
    mesh.source_file = path_;
    ++info_.meshes;
    cb_(std::move(mesh), model_.placement);
  }

  /// On disk (not /vsi...): the canonical target must lie under the canonical root folder.
  bool inside_root_on_disk(const std::string& target) const {
    if (root_dir_.rfind("/vsi", 0) == 0) return true;  // VSI paths: the lexical check is all there is
    std::error_code ec;
    const fs::path root = fs::weakly_canonical(root_dir_, ec);
    if (ec) return false;
    const fs::path t = fs::weakly_canonical(target, ec);
    if (ec) return false;
    auto r = root.begin();
    auto p = t.begin();
    for (; r != root.end(); ++r, ++p)
      if (p == t.end() || *r != *p) return false;
    return true;
  }

  /// Parsed COLLADA meshes by path: several placemarks often share one model (trees, lamp posts).
  const Mesh* load(const std::string& target, const std::string& display, const std::string& id) {
    for (auto it = cache_.begin(); it != cache_.end(); ++it)
      if (it->first == target) {
        cache_.splice(cache_.begin(), cache_, it);
        return &cache_.front().second;
      }
    try {
      ColladaInfo cinfo;
      Mesh m = detail::read_collada_bounded(target, display, id, opt_.collada, budget_, problems_, cinfo);
      if (m.faces.empty()) return nullptr;  // NO_GEOMETRY already reported
      cache_.emplace_front(target, std::move(m));
      if (cache_.size() > kCacheSize) cache_.pop_back();
      return &cache_.front().second;
    } catch (const InputError& e) {
      problem(id, "BAD_MODEL", e.what());
      return nullptr;
    }
  }

  static constexpr std::size_t kCacheSize = 8;
  const std::string path_;
  const KmlOptions& opt_;
  const KmlModelCallback& cb_;
  std::vector<Problem>& problems_;
  KmlInfo& info_;
  xml::ByteBudget budget_;
  xml::SafeParser* xml_ = nullptr;
  std::string archive_, base_dir_, root_dir_;
  std::vector<std::string> stack_;
  bool saw_kml_root_ = false, capturing_ = false;
  std::string text_;
  std::size_t in_placemark_ = 0, in_model_ = 0, in_network_link_ = 0;
  std::size_t placemark_no_ = 0, pm_models_ = 0, capture_depth_ = 0;
  std::string pm_id_, pm_name_, nl_href_, nl_id_;
  Model model_;
  std::list<std::pair<std::string, Mesh>> cache_;
  struct Link {
    std::string rel;   // inside the archive / the input's folder
    std::size_t depth = 0;
    std::string from;  // the linking file, for messages
  };
  std::vector<Link> pending_;            // NetworkLinks to read, in the order met
  std::set<std::string> visited_;        // .kml files read or queued (rel paths)
  std::size_t depth_ = 0;                // NetworkLink depth of the file being parsed
};

int hex(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

HrefStatus resolve_href(const std::string& href_in, const std::string& base_dir, std::string& resolved) {
  resolved.clear();
  const std::string href = trim(href_in);
  if (href.empty()) return HrefStatus::Empty;
  // A scheme ("http:", "file:", "data:" ...): never fetched. One letter and a slash is a drive.
  const auto colon = href.find(':');
  if (colon != std::string::npos && colon > 0) {
    bool scheme = std::isalpha(static_cast<unsigned char>(href[0]));
    for (std::size_t i = 1; i < colon && scheme; ++i) {
      const char c = href[i];
      scheme = std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
    }
    if (scheme) return colon == 1 ? HrefStatus::Absolute : HrefStatus::Remote;
  }
  // Percent-decoding before the path checks: %2e%2e%2f is "../".
  std::string path;
  for (std::size_t i = 0; i < href.size(); ++i) {
    char c = href[i];
    if (c == '%' && i + 2 < href.size() + 0 && hex(href[i + 1]) >= 0 && hex(href[i + 2]) >= 0) {
      c = static_cast<char>(hex(href[i + 1]) * 16 + hex(href[i + 2]));
      i += 2;
    }
    if (static_cast<unsigned char>(c) < 0x20) return HrefStatus::Invalid;
    path.push_back(c == '\\' ? '/' : c);
  }
  if (path.front() == '/') return HrefStatus::Absolute;
  std::vector<std::string> parts;
  auto push = [&](std::string_view p) {
    std::size_t start = 0;
    while (start <= p.size()) {
      const auto slash = p.find('/', start);
      const std::string_view seg = p.substr(start, (slash == std::string_view::npos ? p.size() : slash) - start);
      if (seg == "..") {
        if (parts.empty()) return false;
        parts.pop_back();
      } else if (!seg.empty() && seg != ".") {
        parts.emplace_back(seg);
      }
      if (slash == std::string_view::npos) break;
      start = slash + 1;
    }
    return true;
  };
  if (!push(base_dir) || !push(path)) return HrefStatus::Escapes;
  if (parts.empty()) return HrefStatus::Empty;
  for (std::size_t i = 0; i < parts.size(); ++i) resolved += (i ? "/" : "") + parts[i];
  return HrefStatus::Ok;
}

void read_kml(const std::string& path, const KmlOptions& options, const KmlModelCallback& on_model,
              std::vector<Problem>& problems, KmlInfo& info) {
  info = KmlInfo{};
  Reader reader(path, options, on_model, problems, info);
  reader.run();
}

}  // namespace groundplan::gis
