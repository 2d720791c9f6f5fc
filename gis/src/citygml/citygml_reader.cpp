// SPDX-License-Identifier: MIT
// Streaming CityGML reader (issue 6). expat in namespace mode: every element arrives as
// "URI<space>local", so prefixes (and default namespaces) never matter; CityGML 1.0/2.0/3.0 are told
// apart by the namespace URI family http://www.opengis.net/citygml/... and local names.
//
// One BuildingCtx per Building/BuildingPart in flight (a stack, parts nest); polygons are appended to
// its Mesh as they close. Geometry the ground plan must not see (rooms, installations, furniture,
// storeys) goes to a side mesh that only serves as an xlink target. xlinks resolve, in order: inside
// the building (a reference to a polygon the building already has adds nothing: lod2Solid members
// pointing at the thematic surfaces' polygons would otherwise double every face), in enclosing
// buildings, in a bounded index of recently delivered buildings, and forward, by holding the building
// back (bounded) until a later building defines the target.
#include <groundplan/error.h>
#include <groundplan/gis/citygml.h>
#include <groundplan/gis/citygml_chunks.h>

#include "citygml/coordinates.h"
#include "coordinate_limit.h"
#include "citygml/element_names.h"
#include "citygml/file_problems.h"
#include "xml/block_cache.h"
#include "xml/dom_events.h"

#include <cpl_vsi.h>
#include <expat.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <deque>
#include <exception>
#include <map>
#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <new>

namespace groundplan::gis {
namespace {

constexpr char kSep = ' ';  // namespace URI / local name separator: URIs cannot hold a space
constexpr int kChunk = 1 << 20;
constexpr std::uint8_t kNoLod = 255;

using citygml::Attrs;
using citygml::NameSplitter;
using citygml::Ns;
using citygml::Tag;
using citygml::parse_lod_property;
using citygml::srs_dimension_value;

struct IdRange {
  bool side = false;  // in the side mesh (rooms, installations ...)
  std::uint32_t first = 0, last = 0;  // faces [first, last)
};

struct XRef {
  std::string id;
  SurfaceKind kind = SurfaceKind::Unknown;
  std::uint8_t lod = kNoLod;
  bool flip = false;
  bool side = false;  // the reference itself sits in excluded geometry
};

struct BuildingCtx {
  Mesh mesh;
  Mesh side;
  std::unordered_map<std::string, IdRange> ids;
  std::vector<XRef> refs;
  std::size_t depth = 0;
  bool is_part = false;
  bool has_parts = false;
  std::string foreign_gml_ns;  // first namespace URI of a GML-named element (Polygon, posList ...) that is not GML's
  // code -> (count, first reason): one Problem per code per building
  std::map<std::string, std::pair<std::size_t, std::string>> defects;

  void defect(const std::string& code, const std::string& reason) {
    auto& d = defects[code];
    if (d.first++ == 0) d.second = reason;
  }
};

/// A delivered building kept for backward xlinks from later buildings.
struct IndexedBuilding {
  Mesh mesh;
  Mesh side;
  std::unordered_map<std::string, IdRange> ids;
  std::size_t vertices = 0;
};

struct Frame {
  Tag tag = Tag::None;
  std::uint8_t lod = kNoLod;
  SurfaceKind kind = SurfaceKind::Unknown;
  bool flip = false;
  bool excluded = false;
  std::uint8_t dim = 0;  // srsDimension in force, 0 = not said
};

struct IdMark {
  std::string id;
  std::size_t depth;
  std::uint32_t first_face;
  bool side;
};

enum class Capture : std::uint8_t { None, Coords, Name, MeasuredHeight, EnvLower, EnvUpper, EnvPos };

void copy_faces(const Mesh& from, std::uint32_t first, std::uint32_t last, Mesh& to, const XRef& ref) {
  std::vector<std::vector<Point3>> rings;
  for (std::uint32_t f = first; f < last; ++f) {
    const MeshFace& face = from.faces[f];
    rings.clear();
    for (std::uint32_t r = face.first_ring; r < face.first_ring + face.ring_count; ++r) {
      std::vector<Point3> ring;
      for (std::uint32_t k = from.ring_offsets[r]; k < from.ring_offsets[r + 1]; ++k)
        ring.push_back(from.vertices[from.indices[k]]);
      if (ref.flip) std::reverse(ring.begin() + 1, ring.end());
      rings.push_back(std::move(ring));
    }
    SurfaceKind kind = ref.kind != SurfaceKind::Unknown ? ref.kind : face.kind;
    std::uint8_t lod = ref.lod != kNoLod ? ref.lod : face.lod;
    to.add_face(rings, kind, lod);
  }
}

class Reader : private xml::DomEvents::Sink {
 public:
  /// `watch`: set when this reader reads one chunk of a file (citygml_chunks.h); it then records what
  /// could make the chunk read differently from the whole file, and leaves file-level problems out.
  Reader(const std::string& name, const CityGmlOptions& opt, const MeshCallback& cb, std::vector<Problem>& problems,
         SourceInfo& info, CityGmlChunkWatch* watch = nullptr)
      : name_(name), opt_(opt), cb_(cb), problems_(problems), info_(info), watch_(watch) {
    info_.file = name;
    parser_ = XML_ParserCreateNS(nullptr, kSep);
    if (!parser_) throw Error("out of memory creating the XML parser");
    XML_SetUserData(parser_, this);
    XML_SetElementHandler(parser_, &Reader::on_start, &Reader::on_end);
    // Hostile input (issue 6): no DTD loading, no parameter entities, and any entity declaration
    // stops the parse (billion laughs, external entities such as file:///etc/passwd). No external
    // entity handler is installed, so expat never opens anything.
    XML_SetParamEntityParsing(parser_, XML_PARAM_ENTITY_PARSING_NEVER);
    XML_SetEntityDeclHandler(parser_, &Reader::on_entity_decl);
    XML_SetUnparsedEntityDeclHandler(parser_, &Reader::on_unparsed_entity_decl);
    XML_SetStartDoctypeDeclHandler(parser_, &Reader::on_doctype);
    frames_.reserve(64);
    frames_.push_back(Frame{});
  }
  ~Reader() {
    XML_ParserFree(parser_);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  /// Feeds one chunk; `last` on the final one. Throws on any error.
  void feed(const char* data, std::size_t n, bool last) {
    void* buf = XML_GetBuffer(parser_, static_cast<int>(n > 0 ? n : 1));
    if (!buf) throw Error("out of memory in the XML parser reading " + name_);
    if (n) std::memcpy(buf, data, n);
    parse_buffer(n, last);
  }

  /// Reads straight into expat's buffer (no copy). Returns bytes read.
  /// `may_end`: a read of 0 bytes is the end of the document (false: the caller ends it).
  template <class ReadFn>
  std::size_t feed_from(ReadFn&& read, bool may_end = true) {
    void* buf = XML_GetBuffer(parser_, kChunk);
    if (!buf) throw Error("out of memory in the XML parser reading " + name_);
    std::size_t n = read(buf, static_cast<std::size_t>(kChunk));
    parse_buffer(n, may_end && n == 0);
    return n;
  }

  /// Reads the whole document [data, data + n) through pugixml (xml/dom_events.h), handing the
  /// same events as expat. False, with nothing read, when the document is left to expat (larger than
  /// CityGmlOptions::dom_max_bytes, or one pugixml would read otherwise); then feed() the same bytes.
  bool read_dom(const char* data, std::size_t n) {
    if (n == 0) {  // expat says what an empty document is
      streamed_because("the document is empty");
      return false;
    }
    if (n > opt_.dom_max_bytes) {
      streamed_because(too_large());
      return false;
    }
    xml::DomEvents dom;
    if (std::string why = dom.load(data, n); !why.empty()) {
      streamed_because(std::move(why));
      return false;
    }
    info_.bytes += n;
    dom_ = &dom;
    struct Detach {
      xml::DomEvents*& dom;
      ~Detach() { dom = nullptr; }
    } detach{dom_};
    dom.walk(*this);
    if (!stop_reason_.empty()) {
      salvage(stop_reason_);
      throw InputError(name_ + ": " + stop_reason_);
    }
    return true;
  }

  /// Says (SourceInfo::streamed_why) why the document goes to expat; the first reason is kept.
  void streamed_because(std::string why) {
    if (info_.streamed_why.empty()) info_.streamed_why = std::move(why);
  }
  /// Why a document past CityGmlOptions::dom_max_bytes is streamed.
  std::string too_large() const {
    return opt_.dom_max_bytes ? "larger than " + std::to_string(opt_.dom_max_bytes) + " bytes" : "parsing in memory is off";
  }

  void finish() {
    // Buildings still waiting for a forward xlink target: the target never came.
    while (!pending_.empty()) {
      auto ctx = std::move(pending_.front());
      pending_.pop_front();
      give_up_refs(*ctx);
      deliver(std::move(ctx));
    }
    if (!watch_) detail::add_file_problems(info_, name_, problems_);  // chunks: merge_citygml_chunks says them
  }

 private:
  void parse_buffer(std::size_t n, bool last) {
    info_.bytes += n;
    info_.bytes_streamed += n;
    if (last && info_.bytes == 0) throw InputError(name_ + ": the file is empty (0 bytes): nothing to read");
    XML_Status st = XML_ParseBuffer(parser_, static_cast<int>(n), last ? XML_TRUE : XML_FALSE);
    if (pending_exception_) std::rethrow_exception(pending_exception_);
    if (!stop_reason_.empty()) {
      salvage(stop_reason_);
      throw InputError(name_ + ": " + stop_reason_);
    }
    if (st != XML_STATUS_OK) {
      XML_Error code = XML_GetErrorCode(parser_);
      std::string msg = name_ + ": not well-formed XML at line " + std::to_string(XML_GetCurrentLineNumber(parser_)) +
                        ", column " + std::to_string(XML_GetCurrentColumnNumber(parser_)) + ": " +
                        XML_ErrorString(code);
      if (code == XML_ERROR_NO_ELEMENTS || code == XML_ERROR_UNCLOSED_TOKEN || code == XML_ERROR_PARTIAL_CHAR ||
          code == XML_ERROR_UNCLOSED_CDATA_SECTION)
        msg += " (the file looks truncated; buildings before this point were read)";
      else
        msg += " (is this a CityGML file?)";
      salvage(std::string("the XML breaks off (") + XML_ErrorString(code) + " at line " +
              std::to_string(XML_GetCurrentLineNumber(parser_)) + ")");
      throw InputError(msg);
    }
  }

  /// Reading stops early (truncated or refused file): what is complete still goes out (buildings held
  /// back for a forward xlink), and every building open at that point is named by a Problem TRUNCATED,
  /// so that none is lost silently (issue 8). Deeply nested hostile input may hold hundreds of open
  /// buildings: past kMaxNamed the rest are counted in the last Problem's reason, not listed.
  void salvage(const std::string& why) {
    while (!pending_.empty()) {
      auto ctx = std::move(pending_.front());
      pending_.pop_front();
      give_up_refs(*ctx);
      deliver(std::move(ctx));
    }
    constexpr std::size_t kMaxNamed = 4;
    const std::size_t open = buildings_.size();
    for (std::size_t k = 0; k < open && k < kMaxNamed; ++k) {
      const BuildingCtx& b = *buildings_[k];
      std::string reason = std::string(b.is_part ? "BuildingPart" : "Building") + " is incomplete: " + why +
                           " inside it; it is not used";
      if (k + 1 == kMaxNamed && open > kMaxNamed)
        reason += " (and " + std::to_string(open - kMaxNamed) + " more buildings nested in it)";
      problems_.push_back(Problem{b.mesh.source_id, name_, "read", "TRUNCATED", reason});
      ++info_.buildings_dropped;
    }
    buildings_.clear();
  }

  void stop(std::string reason) {
    if (stop_reason_.empty()) stop_reason_ = std::move(reason);
    if (!dom_) XML_StopParser(parser_, XML_FALSE);
  }

  /// The line of the element being started or ended, from whichever parser reads.
  std::size_t current_line() const {
    return dom_ ? dom_->line() : static_cast<std::size_t>(XML_GetCurrentLineNumber(parser_));
  }

  // xml::DomEvents::Sink: start() and end() are the reader's own (below).
  bool wants_text() const override { return capture_ != Capture::None; }
  void text(const char* s, std::size_t n) override { append_text(s, n); }
  bool stopped() const override { return !stop_reason_.empty(); }

  static void XMLCALL on_entity_decl(void* ud, const XML_Char* name, int, const XML_Char*, int, const XML_Char*,
                                     const XML_Char*, const XML_Char*, const XML_Char*) {
    auto* self = static_cast<Reader*>(ud);
    self->stop(std::string("the document declares the entity \"") + name +
               "\"; entity declarations are refused (they serve entity-expansion and external-entity attacks, and "
               "CityGML has no use for them)");
  }
  static void XMLCALL on_unparsed_entity_decl(void* ud, const XML_Char* name, const XML_Char*, const XML_Char*,
                                              const XML_Char*, const XML_Char*) {
    on_entity_decl(ud, name, 0, nullptr, 0, nullptr, nullptr, nullptr, nullptr);
  }

  static void XMLCALL on_doctype(void* ud, const XML_Char* name, const XML_Char* sysid, const XML_Char* pubid, int) {
    // An external DTD is never loaded (no external entity handler, parameter entities off): say so,
    // since a document that needs its DTD (default attributes, entities) reads differently here.
    if (!sysid && !pubid) return;
    auto* self = static_cast<Reader*>(ud);
    self->problems_.push_back(Problem{"", self->name_, "read", "NOTE",
                                      std::string("the document names an external DTD (\"") +
                                          std::string(sysid ? sysid : pubid).substr(0, 120) +
                                          "\"); it is never loaded"});
  }

  static void XMLCALL on_start(void* ud, const XML_Char* name, const XML_Char** atts) {
    auto* self = static_cast<Reader*>(ud);
    try {
      self->start(name, atts);
    } catch (...) {
      self->pending_exception_ = std::current_exception();
      XML_StopParser(self->parser_, XML_FALSE);
    }
  }
  static void XMLCALL on_end(void* ud, const XML_Char* name) {
    auto* self = static_cast<Reader*>(ud);
    try {
      self->end();
    } catch (...) {
      self->pending_exception_ = std::current_exception();
      XML_StopParser(self->parser_, XML_FALSE);
    }
  }
  static void XMLCALL on_text(void* ud, const XML_Char* s, int len) {
    static_cast<Reader*>(ud)->append_text(s, static_cast<std::size_t>(len));
  }
  void append_text(const char* s, std::size_t n) {
    // Bounded whatever the document claims or holds (issue 8: a "2 GB coordinate list").
    if (text_.size() + n > opt_.max_coordinate_chars) {
      text_overflow_ = true;
      return;
    }
    text_.append(s, n);
  }

  void begin_capture(Capture c) {
    capture_ = c;
    capture_depth_ = frames_.size() + 1;  // called from start(), before its frame is pushed
    text_.clear();
    text_overflow_ = false;
    XML_SetCharacterDataHandler(parser_, &Reader::on_text);
  }
  void end_capture() {
    capture_ = Capture::None;
    XML_SetCharacterDataHandler(parser_, nullptr);
  }

  BuildingCtx* building() { return buildings_.empty() ? nullptr : buildings_.back().get(); }

  void start(const char* name, const char** atts) override {
    if (skip_depth_) {  // inside a subtree we ignore entirely
      if (++skip_level_ + frames_.size() > opt_.max_depth)
        stop("XML nesting deeper than " + std::to_string(opt_.max_depth) + " levels; refused as hostile or broken");
      return;
    }
    if (frames_.size() > opt_.max_depth) {
      stop("XML nesting deeper than " + std::to_string(opt_.max_depth) + " levels; refused as hostile or broken");
      return;
    }
    const std::size_t depth = frames_.size() + 1;  // this element's depth once its frame is pushed
    const citygml::SplitName split = names_.split(name);
    const std::string_view local = split.local;
    const Ns ns = split.ns;

    Frame f = frames_.back();
    f.tag = Tag::None;
    Attrs a = atts[0] ? citygml::scan_attrs(atts, names_) : Attrs{};
    if (a.srs_name) note_srs(a.srs_name);
    BuildingCtx* b = building();
    if (a.srs_dimension) {
      if (const int d = srs_dimension_value(a.srs_dimension)) {
        f.dim = static_cast<std::uint8_t>(d);
        if (!info_.srs_dimension) info_.srs_dimension = d;
      } else {
        bad_srs_dimension(b, a.srs_dimension);
      }
    }

    if (ns == Ns::CityGml) {
      if (info_.citygml_version.empty()) note_version(split.uri);
      Tag t = citygml::citygml_tag(local);
      std::uint8_t lod;
      SurfaceKind lod_kind;
      if (t == Tag::None && parse_lod_property(local, lod, t, lod_kind)) {
        if (t == Tag::LodSkip) {
          if (b) return begin_skip();
        } else {
          f.lod = lod;
          if (lod_kind != SurfaceKind::Unknown) f.kind = lod_kind;
          if (b && a.href) add_ref(*b, a.href, f);
        }
      }
      f.tag = t;
      switch (t) {
        case Tag::Building:
        case Tag::BuildingPart:
          open_building(t == Tag::BuildingPart, a.gml_id);
          f = Frame{};
          f.tag = t;
          f.dim = frames_.back().dim;
          break;
        case Tag::Ground: f.kind = SurfaceKind::Ground; break;
        case Tag::Roof: f.kind = SurfaceKind::Roof; break;
        case Tag::Wall: f.kind = SurfaceKind::Wall; break;
        case Tag::Closure: f.kind = SurfaceKind::Closure; break;
        case Tag::OtherSurface: f.kind = SurfaceKind::Other; break;
        case Tag::Excluded: f.excluded = true; break;
        case Tag::Skip:
          if (b) return begin_skip();
          break;
        case Tag::MeasuredHeight:
          if (b && depth == b->depth + 1) begin_capture(Capture::MeasuredHeight);
          break;
        default:
          break;
      }
    } else if (ns == Ns::Other && b && b->foreign_gml_ns.empty() && citygml::gml_tag(local) != Tag::None) {
      b->foreign_gml_ns = std::string(split.uri);
    } else if (ns == Ns::Gml) {
      Tag t = citygml::gml_tag(local);
      f.tag = t;
      if (b) {
        if (a.gml_id) ids_.push_back(IdMark{a.gml_id, depth, face_count(*b, f.excluded), f.excluded});
        if (a.href) add_ref(*b, a.href, f);
        switch (t) {
          case Tag::Polygon:
            begin_polygon(a.gml_id);
            break;
          case Tag::Exterior:
          case Tag::Interior:
            if (in_polygon_ && depth == poly_depth_ + 1) ring_role_ = t == Tag::Exterior ? 1 : 2;
            break;
          case Tag::LinearRing:
            if (in_polygon_ && ring_role_) {
              in_ring_ = true;
              ring_.clear();
            }
            break;
          case Tag::PosList:
          case Tag::Pos:
          case Tag::Coordinates:
            if (in_ring_) {
              coord_dim_attr_ = a.srs_dimension ? srs_dimension_value(a.srs_dimension) : 0;
              cs_ = a.cs && *a.cs ? a.cs[0] : ',';
              ts_ = a.ts && *a.ts ? a.ts[0] : ' ';
              decimal_ = a.decimal && *a.decimal ? a.decimal[0] : '.';
              begin_capture(Capture::Coords);
            }
            break;
          case Tag::OrientableSurface:
            if (a.orientation && a.orientation[0] == '-') f.flip = !f.flip;
            break;
          case Tag::Name:
            if (depth == b->depth + 1 && b->mesh.name.empty()) begin_capture(Capture::Name);
            break;
          case Tag::CurveRing:
            if (in_polygon_) {
              b->defect("UNSUPPORTED_GEOMETRY", "gml:Ring (a ring of curve segments) is not supported; polygon " +
                                                    poly_label() + " was dropped");
              poly_ok_ = false;
            }
            break;
          default:
            break;
        }
      } else {
        // Outside buildings only the first envelope matters (where the data lies, for the UTM choice).
        if (t == Tag::Envelope && !info_.has_envelope && !env_done_) in_envelope_ = true;
        if (in_envelope_) {
          if (t == Tag::LowerCorner) begin_capture(Capture::EnvLower);
          else if (t == Tag::UpperCorner) begin_capture(Capture::EnvUpper);
          else if (t == Tag::Pos) begin_capture(Capture::EnvPos);
        }
      }
    }
    frames_.push_back(f);
  }

  void begin_skip() {
    skip_depth_ = true;
    skip_level_ = 1;
  }

  void end() override {
    if (skip_depth_) {
      if (--skip_level_ == 0) skip_depth_ = false;
      return;
    }
    const Frame f = frames_.back();
    const std::size_t depth = frames_.size();
    frames_.pop_back();
    BuildingCtx* b = building();

    if (capture_ != Capture::None && capture_depth_ == depth) finish_capture(b, f);

    if (b) {
      switch (f.tag) {
        case Tag::LinearRing:
          if (in_ring_) finish_ring(*b);
          break;
        case Tag::Exterior:
        case Tag::Interior:
          if (in_polygon_ && depth == poly_depth_ + 1) ring_role_ = 0;
          break;
        case Tag::Polygon:
          if (in_polygon_ && depth == poly_depth_) finish_polygon(*b, f);
          break;
        default:
          break;
      }
      while (!ids_.empty() && ids_.back().depth == depth) {
        IdMark& m = ids_.back();
        std::uint32_t last = face_count(*b, m.side);
        if (last > m.first_face) b->ids.emplace(std::move(m.id), IdRange{m.side, m.first_face, last});
        ids_.pop_back();
      }
      if ((f.tag == Tag::Building || f.tag == Tag::BuildingPart) && depth == b->depth) close_building();
    } else if (f.tag == Tag::Envelope && in_envelope_) {
      in_envelope_ = false;
      env_done_ = true;
      if (env_points_ >= 2) info_.has_envelope = true;
    }
  }

  void finish_capture(BuildingCtx* b, const Frame& f) {
    Capture c = capture_;
    end_capture();
    switch (c) {
      case Capture::Coords:
        if (b) add_coordinates(*b, f);
        break;
      case Capture::Name:
        if (b) {
          std::size_t s = text_.find_first_not_of(" \t\r\n");
          std::size_t e = text_.find_last_not_of(" \t\r\n");
          if (s != std::string::npos) b->mesh.name = text_.substr(s, e - s + 1);
        }
        break;
      case Capture::MeasuredHeight:
        if (b) {
          std::vector<double> v;
          if (detail::parse_numbers(text_, v) == detail::CoordStatus::Ok && v.size() == 1)
            b->mesh.measured_height = v[0];
          else
            b->defect("BAD_ATTRIBUTE", "measuredHeight \"" + text_.substr(0, 40) + "\" is not a number; ignored");
        }
        break;
      case Capture::EnvLower:
      case Capture::EnvUpper:
      case Capture::EnvPos: {
        std::vector<double> v;
        if (detail::parse_numbers(text_, v) != detail::CoordStatus::Ok || v.size() < 2) break;
        bool lower = c == Capture::EnvLower || (c == Capture::EnvPos && env_points_ == 0);
        double* dst = lower ? info_.envelope_lower : info_.envelope_upper;
        for (std::size_t k = 0; k < 3; ++k) dst[k] = k < v.size() ? v[k] : 0;
        ++env_points_;
        break;
      }
      case Capture::None:
        break;
    }
  }

  void bad_srs_dimension(BuildingCtx* b, std::string_view sd) {
    const std::string reason = "srsDimension=\"" + std::string(sd.substr(0, 40)) +
                               "\" is not 2 or 3; ignored (the dimension is taken from the coordinates)";
    if (b) {
      b->defect("BAD_SRS_DIMENSION", reason);
    } else if (!bad_dimension_said_) {
      bad_dimension_said_ = true;
      if (watch_) watch_->file_level_problem = true;
      problems_.push_back(Problem{"", name_, "read", "BAD_SRS_DIMENSION", reason});
    }
  }

  void note_srs(const char* srs) {
    if (info_.srs_name.empty()) {
      info_.srs_name = srs;
    } else if (!info_.srs_mixed && info_.srs_name != srs) {
      info_.srs_mixed = true;
      info_.other_srs_name = srs;
    }
  }

  void note_version(std::string_view uri) {
    // .../citygml/2.0, .../citygml/building/1.0, .../citygml/construction/3.0
    if (uri.size() >= 3) {
      std::string_view tail = uri.substr(uri.size() - 3);
      if (tail[0] >= '0' && tail[0] <= '9' && tail[1] == '.' && tail[2] >= '0' && tail[2] <= '9')
        info_.citygml_version = std::string(tail);
    }
  }

  // --- buildings --------------------------------------------------------------------------------

  void open_building(bool is_part, const char* id) {
    if (is_part) ++info_.building_parts;
    else ++info_.buildings;
    auto ctx = std::make_unique<BuildingCtx>();
    ctx->depth = frames_.size() + 1;  // the frame this start pushes
    ctx->is_part = is_part;
    ctx->mesh.source_file = name_;
    if (id && *id) {
      ctx->mesh.source_id = id;
      if (!building_ids_.insert(ctx->mesh.source_id).second)
        ctx->defect("DUPLICATE_ID", "gml:id \"" + ctx->mesh.source_id +
                                        "\" is used by an earlier building of the file too; both are kept (tell them "
                                        "apart by fp_id in the footprints layer)");
      if (watch_) watch_->building_ids.push_back(ctx->mesh.source_id);
    } else {
      if (watch_) watch_->position_dependent = true;  // the id holds a running count and a line number
      ctx->mesh.source_id = std::string(is_part ? "BuildingPart" : "Building") + "#" +
                            std::to_string(info_.buildings + info_.building_parts) + "@line" +
                            std::to_string(current_line());
    }
    if (BuildingCtx* parent = building()) {
      parent->has_parts = true;
      ctx->mesh.parent_id = parent->mesh.source_id;
    }
    buildings_.push_back(std::move(ctx));
    in_polygon_ = in_ring_ = false;
  }

  void close_building() {
    std::unique_ptr<BuildingCtx> ctx = std::move(buildings_.back());
    buildings_.pop_back();
    resolve_refs(*ctx);
    std::unique_ptr<BuildingCtx> done;
    if (!ctx->refs.empty()) {
      if (pending_.size() >= opt_.max_pending_buildings) {
        // No room to wait any longer: the oldest waiting building goes out with what it has.
        auto oldest = std::move(pending_.front());
        pending_.pop_front();
        give_up_refs(*oldest);
        deliver(std::move(oldest));
      }
      pending_.push_back(std::move(ctx));
      return;
    }
    deliver(std::move(ctx));
  }

  /// Resolves what it can; leaves the rest in ctx.refs.
  void resolve_refs(BuildingCtx& ctx) {
    std::vector<XRef> left;
    for (XRef& r : ctx.refs) {
      auto own = ctx.ids.find(r.id);
      if (own != ctx.ids.end()) {
        // The building has it already: the reference adds nothing, unless the shell points into
        // geometry kept aside (an installation's polygon used in the solid).
        if (own->second.side && !r.side) copy_faces(ctx.side, own->second.first, own->second.last, ctx.mesh, r);
        ++info_.xlinks_resolved;
        continue;
      }
      if (resolve_from_open(ctx, r)) {
        ++info_.xlinks_resolved;
        continue;
      }
      if (resolve_from_index(ctx, r)) {
        ++info_.xlinks_resolved;
        if (watch_) watch_->cross_building_xlink = true;  // the target may sit in an earlier chunk
        continue;
      }
      left.push_back(std::move(r));
    }
    ctx.refs = std::move(left);
  }

  bool resolve_from(const Mesh& main, const Mesh& side, const std::unordered_map<std::string, IdRange>& ids,
                    BuildingCtx& ctx, const XRef& r) {
    auto it = ids.find(r.id);
    if (it == ids.end()) return false;
    const IdRange& range = it->second;
    copy_faces(range.side ? side : main, range.first, range.last, r.side ? ctx.side : ctx.mesh, r);
    return true;
  }

  bool resolve_from_open(BuildingCtx& ctx, const XRef& r) {
    for (auto& open : buildings_)
      if (resolve_from(open->mesh, open->side, open->ids, ctx, r)) return true;
    return false;
  }

  bool resolve_from_index(BuildingCtx& ctx, const XRef& r) {
    for (auto it = index_.rbegin(); it != index_.rend(); ++it)
      if (resolve_from((*it)->mesh, (*it)->side, (*it)->ids, ctx, r)) return true;
    return false;
  }

  void give_up_refs(BuildingCtx& ctx) {
    if (watch_ && !ctx.refs.empty()) watch_->cross_building_xlink = true;  // the target may sit in another chunk
    for (const XRef& r : ctx.refs) {
      ++info_.xlinks_missing;
      ctx.defect("XLINK_TARGET_MISSING", "xlink:href=\"#" + r.id +
                                             "\" names no geometry found in the file (or too far from the reference "
                                             "to be kept); that surface is missing from the building");
    }
    ctx.refs.clear();
  }

  void deliver(std::unique_ptr<BuildingCtx> ctx) {
    // Keep a copy for backward xlinks from later buildings, before the LoD filter changes face numbers.
    if (opt_.xlink_index_max_vertices > 0 && !ctx->ids.empty()) {
      auto ib = std::make_unique<IndexedBuilding>();
      ib->mesh.vertices = ctx->mesh.vertices;
      ib->mesh.indices = ctx->mesh.indices;
      ib->mesh.ring_offsets = ctx->mesh.ring_offsets;
      ib->mesh.faces = ctx->mesh.faces;
      ib->side = std::move(ctx->side);
      ib->ids = std::move(ctx->ids);
      ib->vertices = ib->mesh.vertices.size() + ib->side.vertices.size();
      index_vertices_ += ib->vertices;
      index_.push_back(std::move(ib));
      while (index_vertices_ > opt_.xlink_index_max_vertices && !index_.empty()) {
        index_vertices_ -= index_.front()->vertices;
        index_.pop_front();
      }
      // Buildings waiting for a forward reference: maybe this one defines it.
      if (!pending_.empty()) retry_pending(*index_.back());
    }
    emit(*ctx);
  }

  void retry_pending(const IndexedBuilding& ib) {
    for (std::size_t k = 0; k < pending_.size();) {
      BuildingCtx& p = *pending_[k];
      std::vector<XRef> left;
      for (XRef& r : p.refs) {
        if (resolve_from(ib.mesh, ib.side, ib.ids, p, r)) {
          ++info_.xlinks_resolved;
          if (watch_) watch_->cross_building_xlink = true;
        }
        else left.push_back(std::move(r));
      }
      p.refs = std::move(left);
      if (p.refs.empty()) {
        auto ctx = std::move(pending_[k]);
        pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(k));
        deliver(std::move(ctx));  // may recurse into retry_pending; indices restart below
        k = 0;
      } else {
        ++k;
      }
    }
  }

  void emit(BuildingCtx& ctx) {
    Mesh& m = ctx.mesh;
    for (auto& [code, d] : ctx.defects) {
      std::string reason = d.second;
      if (d.first > 1) reason += " (and " + std::to_string(d.first - 1) + " more like it)";
      problems_.push_back(Problem{m.source_id, name_, "read", code, reason});
    }
    if (m.faces.empty()) {
      if (ctx.has_parts) return;  // the parts carry the building
      std::string reason = std::string(ctx.is_part ? "BuildingPart" : "Building") +
                           " has no surface geometry (no polygon in any lod0-lod4 property)";
      if (!ctx.foreign_gml_ns.empty())
        reason += "; its geometry elements are in the namespace \"" + ctx.foreign_gml_ns.substr(0, 120) +
                  "\", not GML's (http://www.opengis.net/gml or http://www.opengis.net/gml/3.2)";
      else if (!ctx.defects.empty())
        reason += " left after the defects above";
      problems_.push_back(Problem{m.source_id, name_, "read", "NO_GEOMETRY", reason});
      ++info_.buildings_dropped;
      return;
    }
    // LoD choice: the highest the building has, or the one asked for. Faces without a LoD stay.
    int have = 0;  // bit mask of LoDs present
    for (const MeshFace& f : m.faces)
      if (f.lod <= 4) have |= 1 << f.lod;
    if (have) {
      int want = opt_.lod;
      if (want < 0) {
        want = 4;
        while (!(have & (1 << want))) --want;
      }
      if (!(have & (1 << want))) {
        std::string avail;
        for (int l = 0; l <= 4; ++l)
          if (have & (1 << l)) avail += (avail.empty() ? "" : ", ") + std::to_string(l);
        if (ctx.has_parts) return;
        problems_.push_back(Problem{m.source_id, name_, "read", "NO_GEOMETRY_AT_LOD",
                                    "no geometry at LoD " + std::to_string(want) + " (the building has LoD " + avail +
                                        ")"});
        ++info_.buildings_dropped;
        return;
      }
      if (have != (1 << want)) filter_lod(m, static_cast<std::uint8_t>(want));
    }
    ++info_.meshes;
    info_.faces += m.faces.size();
    cb_(std::move(m));
  }

  static void filter_lod(Mesh& m, std::uint8_t lod) {
    Mesh out;
    out.source_id = std::move(m.source_id);
    out.parent_id = std::move(m.parent_id);
    out.source_file = std::move(m.source_file);
    out.name = std::move(m.name);
    out.measured_height = m.measured_height;
    for (const MeshFace& f : m.faces) {
      if (f.lod != lod && f.lod != kNoLod) continue;
      MeshFace nf = f;
      nf.first_ring = static_cast<std::uint32_t>(out.ring_count());
      for (std::uint32_t r = f.first_ring; r < f.first_ring + f.ring_count; ++r) {
        for (std::uint32_t k = m.ring_offsets[r]; k < m.ring_offsets[r + 1]; ++k) {
          out.indices.push_back(static_cast<std::uint32_t>(out.vertices.size()));
          out.vertices.push_back(m.vertices[m.indices[k]]);
        }
        out.ring_offsets.push_back(static_cast<std::uint32_t>(out.indices.size()));
      }
      out.faces.push_back(nf);
    }
    m = std::move(out);
  }

  static std::uint32_t face_count(const BuildingCtx& b, bool side) {
    return static_cast<std::uint32_t>(side ? b.side.faces.size() : b.mesh.faces.size());
  }

  void add_ref(BuildingCtx& b, const char* href, const Frame& f) {
    if (href[0] != '#') {
      b.defect("EXTERNAL_XLINK", std::string("xlink:href=\"") + std::string(href).substr(0, 120) +
                                     "\" points outside the file; external references are never followed");
      return;
    }
    XRef r;
    r.id = href + 1;
    r.kind = f.kind;
    r.lod = f.lod;
    r.flip = f.flip;
    r.side = f.excluded;
    // OrientableSurface orientation="-" on the referencing element itself
    b.refs.push_back(std::move(r));
  }

  // --- polygons ---------------------------------------------------------------------------------

  void begin_polygon(const char* id) {
    in_polygon_ = true;
    poly_ok_ = true;
    poly_depth_ = frames_.size() + 1;
    poly_points_.clear();
    poly_ring_ends_.clear();
    poly_exterior_ = 0;
    poly_has_exterior_ = false;
    poly_id_ = id ? id : "";
    ring_role_ = 0;
    in_ring_ = false;
  }

  std::string poly_label() const {
    if (watch_ && poly_id_.empty()) watch_->position_dependent = true;
    return poly_id_.empty() ? "at line " + std::to_string(current_line()) : "\"" + poly_id_ + "\"";
  }

  void add_coordinates(BuildingCtx& b, const Frame& f) {
    coords_.clear();
    if (text_overflow_) {
      if (poly_ok_)
        b.defect("BAD_COORDINATES", "polygon " + poly_label() + ": coordinate list longer than " +
                                        std::to_string(opt_.max_coordinate_chars) + " characters; dropped");
      poly_ok_ = false;
      return;
    }
    detail::CoordStatus st;
    int dim = 0;
    if (f.tag == Tag::Coordinates) {
      st = detail::parse_gml_coordinates(text_, cs_, ts_, decimal_, coords_, dim);
      if (st == detail::CoordStatus::Ok && dim != 2 && dim != 3) st = detail::CoordStatus::BadNumber;
    } else {
      st = detail::parse_numbers(text_, coords_);
      if (st == detail::CoordStatus::Ok) {
        if (f.tag == Tag::Pos) {
          dim = static_cast<int>(coords_.size());
        } else if (coord_dim_attr_ == 2 || coord_dim_attr_ == 3) {
          dim = coord_dim_attr_;
        } else if (f.dim) {
          dim = f.dim;
        } else {
          if (watch_) watch_->dimension_defaults |= 1u << info_.srs_dimension;
          dim = detail::infer_dimension(coords_, 0, info_.srs_dimension ? info_.srs_dimension : 3);
        }
        if ((dim != 2 && dim != 3) || coords_.size() % static_cast<std::size_t>(dim) != 0)
          st = detail::CoordStatus::BadNumber;
      }
    }
    if (st != detail::CoordStatus::Ok) {
      if (poly_ok_) {
        if (st == detail::CoordStatus::NotFinite)
          b.defect("NOT_FINITE", "polygon " + poly_label() + " has a NaN or infinite coordinate; dropped");
        else
          b.defect("BAD_COORDINATES", "polygon " + poly_label() + ": \"" + text_.substr(0, 60) +
                                          "\" is not a list of 2D/3D coordinates; dropped");
      }
      poly_ok_ = false;
      return;
    }
    for (double v : coords_) {
      if (std::fabs(v) > opt_.max_abs_coordinate) {
        if (poly_ok_) {
          b.defect("COORDINATE_OUT_OF_RANGE",
                   "polygon " + poly_label() + ": " + beyond_coordinate_limit(v, opt_.max_abs_coordinate) + "; dropped");
        }
        poly_ok_ = false;
        return;
      }
    }
    for (std::size_t k = 0; k + dim <= coords_.size(); k += static_cast<std::size_t>(dim))
      ring_.push_back(Point3{coords_[k], coords_[k + 1], dim == 3 ? coords_[k + 2] : 0.0});
  }

  void finish_ring(BuildingCtx& b) {
    in_ring_ = false;
    if (!poly_ok_) return;
    if (ring_.size() >= 2 && ring_.front() == ring_.back()) ring_.pop_back();
    std::size_t distinct = 0;
    for (std::size_t k = 0; k < ring_.size(); ++k)
      if (k == 0 || !(ring_[k] == ring_[k - 1])) ++distinct;
    if (distinct < 3) {
      if (ring_role_ == 1) {
        b.defect("TOO_FEW_POINTS", "polygon " + poly_label() + ": exterior ring has " + std::to_string(distinct) +
                                       " distinct points (at least 3 needed); dropped");
        poly_ok_ = false;
      } else {
        b.defect("TOO_FEW_POINTS", "polygon " + poly_label() + ": interior ring has " + std::to_string(distinct) +
                                       " distinct points; that hole was dropped");
      }
      return;
    }
    if (ring_role_ == 1) {
      if (poly_has_exterior_) {
        poly_ok_ = false;
        b.defect("BAD_POLYGON", "polygon " + poly_label() + " has two exterior rings; dropped");
        return;
      }
      poly_has_exterior_ = true;
      poly_exterior_ = poly_ring_ends_.size();
    }
    poly_points_.insert(poly_points_.end(), ring_.begin(), ring_.end());
    poly_ring_ends_.push_back(static_cast<std::uint32_t>(poly_points_.size()));
  }

  void finish_polygon(BuildingCtx& b, const Frame& f) {
    in_polygon_ = false;
    if (!poly_ok_) return;
    if (!poly_has_exterior_) {
      b.defect("BAD_POLYGON", "polygon " + poly_label() + " has no exterior ring; dropped");
      return;
    }
    add_polygon_face(f.excluded ? b.side : b.mesh, f);
  }

  /// The polygon's rings as one face, the exterior first, then the holes in document order; an
  /// orientation="-" surface reversed (the first point kept). What Mesh::add_face makes, without a
  /// vector per ring.
  void add_polygon_face(Mesh& m, const Frame& f) {
    MeshFace face;
    face.first_ring = static_cast<std::uint32_t>(m.ring_count());
    face.ring_count = static_cast<std::uint32_t>(poly_ring_ends_.size());
    face.kind = f.kind;
    face.lod = f.lod;
    auto put = [&](std::size_t r) {
      const std::size_t begin = r == 0 ? 0 : poly_ring_ends_[r - 1], end = poly_ring_ends_[r];
      auto push = [&](const Point3& p) {
        m.indices.push_back(static_cast<std::uint32_t>(m.vertices.size()));
        m.vertices.push_back(p);
      };
      push(poly_points_[begin]);
      if (f.flip)
        for (std::size_t k = end - 1; k > begin; --k) push(poly_points_[k]);
      else
        for (std::size_t k = begin + 1; k < end; ++k) push(poly_points_[k]);
      m.ring_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()));
    };
    put(poly_exterior_);
    for (std::size_t r = 0; r < poly_ring_ends_.size(); ++r)
      if (r != poly_exterior_) put(r);
    m.faces.push_back(face);
  }

  std::string name_;
  const CityGmlOptions& opt_;
  const MeshCallback& cb_;
  std::vector<Problem>& problems_;
  SourceInfo& info_;
  CityGmlChunkWatch* watch_ = nullptr;
  XML_Parser parser_ = nullptr;
  xml::DomEvents* dom_ = nullptr;  // set while read_dom() walks a document
  NameSplitter names_;
  std::exception_ptr pending_exception_;
  std::string stop_reason_;

  std::vector<Frame> frames_;
  bool skip_depth_ = false;
  std::size_t skip_level_ = 0;
  std::vector<std::unique_ptr<BuildingCtx>> buildings_;
  std::vector<IdMark> ids_;
  std::deque<std::unique_ptr<BuildingCtx>> pending_;
  std::deque<std::unique_ptr<IndexedBuilding>> index_;
  std::size_t index_vertices_ = 0;

  Capture capture_ = Capture::None;
  std::size_t capture_depth_ = 0;
  std::string text_;
  bool text_overflow_ = false;
  std::vector<double> coords_;
  std::unordered_set<std::string> building_ids_;  // for DUPLICATE_ID
  bool bad_dimension_said_ = false;
  int coord_dim_attr_ = 0;
  char cs_ = ',', ts_ = ' ', decimal_ = '.';

  bool in_polygon_ = false, poly_ok_ = false, poly_has_exterior_ = false, in_ring_ = false;
  std::size_t poly_depth_ = 0;
  int ring_role_ = 0;  // 1 exterior, 2 interior
  std::string poly_id_;
  std::vector<Point3> poly_points_;             // the polygon's rings one after the other
  std::vector<std::uint32_t> poly_ring_ends_;   // where each ring ends in poly_points_
  std::size_t poly_exterior_ = 0;               // which ring is the exterior
  std::vector<Point3> ring_;

  bool in_envelope_ = false, env_done_ = false;
  int env_points_ = 0;
};

}  // namespace

namespace detail {
void add_file_problems(const SourceInfo& info, const std::string& name, std::vector<Problem>& problems) {
  if (info.citygml_version.empty()) {
    problems.push_back(Problem{"", name, "read", "NOT_CITYGML",
                               "no CityGML namespace (http://www.opengis.net/citygml/...) in the file: "
                               "nothing read from it"});
  }
  if (info.srs_mixed) {
    problems.push_back(Problem{"", name, "read", "MIXED_SRS",
                               "the file uses srsName \"" + info.srs_name + "\" and also \"" + info.other_srs_name +
                                   "\"; every coordinate is taken as in the first"});
  }
}
}  // namespace detail

namespace {
struct VsiClose {
  void operator()(VSILFILE* f) const { VSIFCloseL(f); }
};
using VsiHandle = std::unique_ptr<VSILFILE, VsiClose>;

VsiHandle open_file(const std::string& path) {
  VsiHandle f(VSIFOpenL(path.c_str(), "rb"));
  if (!f) throw InputError(path + ": cannot open the file (does it exist and is it readable?)");
  return f;
}

/// Bytes read into memory for the DOM path, without zero-filling them first, in memory kept by the
/// thread between documents (xml/block_cache.h).
class ByteBuffer {
 public:
  ByteBuffer() = default;
  ByteBuffer(const ByteBuffer&) = delete;
  ByteBuffer& operator=(const ByteBuffer&) = delete;
  ~ByteBuffer() { xml::cached_free(bytes_); }
  char* data() { return bytes_; }
  std::size_t size() const { return size_; }
  /// Room for `extra` more bytes past size(); returns where they go.
  char* grow(std::size_t extra) {
    if (size_ + extra > capacity_) {
      const std::size_t cap = std::max(size_ + extra, 2 * capacity_);
      char* bigger = static_cast<char*>(xml::cached_alloc(cap));
      if (!bigger) throw std::bad_alloc();
      if (size_) std::memcpy(bigger, bytes_, size_);
      xml::cached_free(bytes_);
      bytes_ = bigger;
      capacity_ = cap;
    }
    return bytes_ + size_;
  }
  void append(const char* s, std::size_t n) {
    if (n) std::memcpy(grow(n), s, n);
    size_ += n;
  }
  void added(std::size_t n) { size_ += n; }

 private:
  char* bytes_ = nullptr;
  std::size_t size_ = 0, capacity_ = 0;
};

/// Gives `reader` the bytes [data, data + n) through expat, in pieces of at most kChunk.
void feed_expat(Reader& reader, const char* data, std::size_t n) {
  for (std::size_t off = 0; off < n; off += kChunk) reader.feed(data + off, std::min<std::size_t>(kChunk, n - off), false);
}
}  // namespace

void read_citygml(const std::string& path, const CityGmlOptions& options, const MeshCallback& on_mesh,
                  std::vector<Problem>& problems, SourceInfo& info) {
  const VsiHandle file = open_file(path);
  VSILFILE* fp = file.get();
  Reader reader(path, options, on_mesh, problems, info);
  // Up to dom_max_bytes into memory: a file that ends within them is read through pugixml. A larger one
  // (or one pugixml would read otherwise) is given to expat, those bytes first, then streamed.
  ByteBuffer head;
  bool ended = false;
  VSIStatBufL st;  // room for the whole file at once where its size is known cheaply (not through a gzip)
  if (!ended && path.rfind("/vsigzip/", 0) != 0 && VSIStatExL(path.c_str(), &st, VSI_STAT_SIZE_FLAG) == 0 &&
      static_cast<std::uint64_t>(st.st_size) <= options.dom_max_bytes)
    head.grow(static_cast<std::size_t>(st.st_size) + kChunk);
  while (options.dom_max_bytes && !ended && head.size() <= options.dom_max_bytes) {
    const std::size_t n = VSIFReadL(head.grow(kChunk), 1, kChunk, fp);
    head.added(n);
    if (options.on_bytes && n) options.on_bytes(n);
    ended = n < static_cast<std::size_t>(kChunk);
  }
  if (ended && reader.read_dom(head.data(), head.size())) {
    reader.finish();
    return;
  }
  if (!ended) reader.streamed_because(reader.too_large());
  feed_expat(reader, head.data(), head.size());
  for (;;) {
    std::size_t n = reader.feed_from([&](void* buf, std::size_t cap) { return VSIFReadL(buf, 1, cap, fp); });
    if (options.on_bytes && n) options.on_bytes(n);
    if (n == 0) break;
  }
  reader.finish();
}

void read_citygml_buffer(std::string_view xml, const std::string& name, const CityGmlOptions& options,
                         const MeshCallback& on_mesh, std::vector<Problem>& problems, SourceInfo& info) {
  Reader reader(name, options, on_mesh, problems, info);
  if (!reader.read_dom(xml.data(), xml.size())) {
    feed_expat(reader, xml.data(), xml.size());
    reader.feed(nullptr, 0, true);
  }
  reader.finish();
}

void read_citygml_chunk(const std::string& path, const CityGmlChunkPlan& plan, std::size_t k,
                        const CityGmlOptions& options, const MeshCallback& on_mesh, std::vector<Problem>& problems,
                        SourceInfo& info, CityGmlChunkWatch& watch) {
  const std::uint64_t begin = plan.ranges.at(k).first, end = plan.ranges.at(k).second;  // lambdas capture these
  const bool last = k + 1 == plan.ranges.size();
  const VsiHandle file = open_file(path);
  VSILFILE* fp = file.get();
  if (VSIFSeekL(fp, begin, SEEK_SET) != 0) throw InputError(path + ": cannot seek to byte " + std::to_string(begin));
  Reader reader(path, options, on_mesh, problems, info, &watch);
  const auto read_range = [&](const auto& take) {
    std::uint64_t left = end - begin;
    while (left > 0) {
      const std::size_t n = take(static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, left)));
      if (n == 0)
        throw InputError(path + ": the file ends before byte " + std::to_string(end) + " (changed while read?)");
      left -= n;
      if (options.on_bytes) options.on_bytes(n);
    }
  };
  const std::uint64_t whole = plan.head.size() + (end - begin) + (last ? 0 : plan.tail.size());
  if (whole <= options.dom_max_bytes) {
    // The chunk as one document in memory (head, range, tail), read through pugixml.
    ByteBuffer doc;
    doc.grow(static_cast<std::size_t>(whole));
    doc.append(plan.head.data(), plan.head.size());
    read_range([&](std::size_t cap) {
      const std::size_t n = VSIFReadL(doc.grow(cap), 1, cap, fp);
      doc.added(n);
      return n;
    });
    if (!last) doc.append(plan.tail.data(), plan.tail.size());
    if (!reader.read_dom(doc.data(), doc.size())) {
      feed_expat(reader, doc.data(), doc.size());
      reader.feed(nullptr, 0, true);
    }
    reader.finish();
    return;
  }
  reader.streamed_because(reader.too_large());
  reader.feed(plan.head.data(), plan.head.size(), false);
  read_range([&](std::size_t cap) {
    return reader.feed_from([&](void* buf, std::size_t) { return VSIFReadL(buf, 1, cap, fp); }, false);
  });
  if (!last) reader.feed(plan.tail.data(), plan.tail.size(), false);
  reader.feed(nullptr, 0, true);
  reader.finish();
}

bool looks_like_citygml(std::string_view head) {
  return head.find("http://www.opengis.net/citygml/") != std::string_view::npos &&
         (head.find("CityModel") != std::string_view::npos || head.find("Building") != std::string_view::npos);
}

}  // namespace groundplan::gis
