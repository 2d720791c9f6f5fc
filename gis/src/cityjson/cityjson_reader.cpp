// SPDX-License-Identifier: MIT
// CityJSON and CityJSONSeq front ends (issue 16). Why simdjson: reading must beat GML by a wide margin
// (>= 200 MB/s per core). A valid CityJSON file is parsed once into simdjson's DOM (the library's
// runtime-dispatched AVX2/AVX-512 kernel: Debian's simdjson 3.0.1 gives On-Demand only the portable one
// without -march), with the parser and the file's buffer kept per thread between files (first-touch page
// faults of a fresh parser cost more than the parse). CityJSON puts "vertices" anywhere among the
// top-level keys (3DBAG: after "CityObjects"), so the whole document is needed before any object.
// Where the DOM parse fails (a broken object), the file is read again object by object: an On-Demand
// pass takes transform, metadata, templates and vertices, a second hands each city object's text to a
// small DOM parser, so one malformed object is a Problem naming it, not the file's end.
// CityJSONSeq (one JSON document per line) is read line by line through a bounded buffer.
#include <groundplan/error.h>
#include <groundplan/gis/cityjson.h>

#include "cityjson/city_objects.h"

#include <cpl_vsi.h>
#include <simdjson.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>

namespace groundplan::gis {
namespace {

namespace dom = simdjson::dom;
namespace ondemand = simdjson::ondemand;
using cityjson::ObjectConverter;
using cityjson::Templates;
using cityjson::Transform;

struct VsiFile {
  VSILFILE* f = nullptr;
  ~VsiFile() {
    if (f) VSIFCloseL(f);
  }
};

VSILFILE* open_or_throw(const std::string& path, VsiFile& holder) {
  holder.f = VSIFOpenL(path.c_str(), "rb");
  if (!holder.f) throw InputError(path + ": cannot open the file (does it exist and is it readable?)");
  return holder.f;
}

void read_metadata(dom::element meta, CityJsonInfo& info) {
  std::string_view rs;
  if (meta["referenceSystem"].get_string().get(rs) == simdjson::SUCCESS) info.reference_system = std::string(rs.substr(0, 4096));
  dom::array ext;
  if (meta["geographicalExtent"].get_array().get(ext) == simdjson::SUCCESS && ext.size() == 6) {
    bool ok = true;
    for (std::size_t i = 0; i < 6 && ok; ++i) ok = ext.at(i).get_double().get(info.extent[i]) == simdjson::SUCCESS;
    info.has_extent = ok;
  }
}

/// A fresh DOM parser limited to `max_depth` nesting.
std::unique_ptr<dom::parser> make_dom_parser(std::size_t max_depth) {
  auto p = std::make_unique<dom::parser>();
  if (p->allocate(1 << 16, max_depth) != simdjson::SUCCESS) throw std::bad_alloc();
  return p;
}

/// Vertices of a DOM array ("vertices" of a CityJSONSeq feature), walked once: an index lookup
/// (`array::at`) walks from the array's start, and this runs once per vertex of every line.
void read_vertices(dom::array a, const Transform& t, std::vector<Point3>& out, std::size_t& bad) {
  out.clear();
  out.reserve(a.size());
  for (dom::element v : a) {
    double xyz[3] = {0, 0, 0};
    dom::array c;
    bool ok = v.get_array().get(c) == simdjson::SUCCESS;
    std::size_t k = 0;
    if (ok)
      for (dom::element e : c) {
        if (k >= 3 || e.get_double().get(xyz[k]) != simdjson::SUCCESS) ok = false;
        ++k;
      }
    cityjson::add_vertex(out, xyz, ok && k == 3, t, bad);
  }
}

void note_bad_vertices(std::size_t bad, const std::string& where, const std::string& file, std::vector<Problem>& problems) {
  if (bad)
    problems.push_back(Problem{"", file, "read", "NOT_FINITE",
                               where + ": " + std::to_string(bad) +
                                   " vertices are not three numbers in double range; surfaces using them are dropped"});
}

/// The text of an object value (throws simdjson_error when it is not an object).
std::string_view object_text(ondemand::value v) {
  ondemand::object o = v.get_object();
  return o.raw_json();
}

}  // namespace

bool looks_like_cityjson(std::string_view head, bool* sequence) {
  const auto first = head.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (first == std::string_view::npos || head[first] != '{') return false;
  // "type": "CityJSON" in the first document (the first line of a sequence).
  const auto line_end = head.find('\n', first);
  const std::string_view doc = head.substr(first, line_end == std::string_view::npos ? std::string_view::npos : line_end - first);
  std::size_t at = 0;
  bool found = false;
  while (!found && (at = doc.find("\"type\"", at)) != std::string_view::npos) {
    at += 6;
    const auto v = doc.find_first_not_of(" \t\r\n:", at);
    found = v != std::string_view::npos && doc.substr(v, 10) == "\"CityJSON\"";
  }
  if (!found && line_end == std::string_view::npos && head.find("\"CityJSON\"") == std::string_view::npos) return false;
  if (!found) {
    // A pretty-printed file: "type" may sit on a later line.
    const auto t = head.find("\"type\"");
    const auto v = t == std::string_view::npos ? t : head.find_first_not_of(" \t\r\n:", t + 6);
    found = v != std::string_view::npos && head.substr(v, 10) == "\"CityJSON\"";
  }
  if (found && sequence) *sequence = line_end != std::string_view::npos && head.find("\"CityJSONFeature\"", line_end) != std::string_view::npos;
  return found;
}

namespace {

/// Asks Linux for transparent huge pages on a large buffer about to be written: one fault per 2 MiB
/// instead of per 4 KiB. On the VMs we measured, first-touch faults of the parser's buffers cost more
/// than the parse itself (tests/bench/RESULTS.md). A hint only; nothing changes where it is refused.
void prefer_huge_pages(const void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kPage = 4096;
  if (bytes < (std::size_t{4} << 20)) return;
  const auto begin = (reinterpret_cast<std::uintptr_t>(p) + kPage - 1) & ~(kPage - 1);
  const auto end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kPage - 1);
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

InputError too_many_bytes(const std::string& path, std::uint64_t max_bytes) {
  return InputError(path + ": unpacks to more than " + std::to_string(max_bytes) +
                    " bytes, the limit for a compressed input (ReadOptions::gzip_max_ratio times its packed size); "
                    "stopped (gzip bomb?). If the file is genuine, unpack it and read the plain file");
}

/// Per reading thread: the file's bytes and a DOM parser, kept from one file to the next, so that their
/// pages are allocated and first touched once per thread rather than once per file (on the machines we
/// measured, page faults cost more than the parse: tests/bench/RESULTS.md). Both are released after a
/// file larger than kKeepBytes, so that a thread does not hold gigabytes between files.
struct Scratch {
  std::unique_ptr<char[]> bytes;
  std::size_t capacity = 0;
  dom::parser whole;
  cityjson::VertexTable vertices;
  bool in_use = false;
};
constexpr std::size_t kKeepBytes = std::size_t{64} << 20;
constexpr std::size_t kReadChunk = std::size_t{1} << 20;  // per VSIFReadL: progress moves while a file is read

/// The thread's Scratch, or a fresh one when the thread is already inside read_cityjson (a callback that
/// waits in TBB may run another file's task on this thread).
class ScratchLease {
 public:
  ScratchLease() {
    thread_local Scratch mine;
    if (mine.in_use) {
      local_ = std::make_unique<Scratch>();
      s_ = local_.get();
    } else {
      s_ = &mine;
    }
    s_->in_use = true;
  }
  ~ScratchLease() {
    s_->in_use = false;
    if (s_->capacity > kKeepBytes) {
      s_->bytes.reset();
      s_->capacity = 0;
      s_->whole = dom::parser{};
      s_->vertices = cityjson::VertexTable{};
    }
  }
  Scratch& operator*() { return *s_; }
  Scratch* operator->() { return s_; }

 private:
  std::unique_ptr<Scratch> local_;
  Scratch* s_ = nullptr;
};

/// The whole file into s.bytes, padded as simdjson needs (GDAL VSI: plain files, /vsigzip/, /vsizip/,
/// /vsimem/). One allocation of the stated size (+ padding) when the size is known. Read 1 MiB at a time,
/// each told to `on_bytes` (progress). Returns the length.
std::size_t load(const std::string& path, std::uint64_t max_bytes, const std::function<void(std::uint64_t)>& on_bytes,
                 Scratch& s) {
  VsiFile holder;
  VSILFILE* f = open_or_throw(path, holder);
  VSIStatBufL st;
  std::size_t stated = 0;
  // Not for /vsigzip/: its size is known only by unpacking it all, and a gzip bomb states what it likes.
  if (path.rfind("/vsigzip/", 0) != 0 && VSIStatL(path.c_str(), &st) == 0 && st.st_size > 0 && static_cast<std::uint64_t>(st.st_size) <= simdjson::SIMDJSON_MAXSIZE_BYTES)
    stated = static_cast<std::size_t>(st.st_size);
  std::size_t length = 0;
  auto grow = [&](std::size_t want) {
    std::unique_ptr<char[]> next(new char[want]);
    prefer_huge_pages(next.get(), want);
    if (length) std::memcpy(next.get(), s.bytes.get(), length);
    s.bytes = std::move(next);
    s.capacity = want;
  };
  // + 1: the read after the last byte finds the end without growing
  if (s.capacity < stated + simdjson::SIMDJSON_PADDING + 1) grow(stated + simdjson::SIMDJSON_PADDING + 1);
  for (;;) {
    if (length > simdjson::SIMDJSON_MAXSIZE_BYTES)
      throw InputError(path + ": larger than 4 GiB, the most a CityJSON file can be read as one document; convert it "
                              "to CityJSONSeq (cjseq cat, or cjio export jsonl) and read the .city.jsonl");
    if (s.capacity - length <= simdjson::SIMDJSON_PADDING) grow(std::max<std::size_t>(2 * s.capacity, 1 << 20));
    const std::size_t want = std::min<std::size_t>(s.capacity - length - simdjson::SIMDJSON_PADDING, kReadChunk);
    const std::size_t got = VSIFReadL(s.bytes.get() + length, 1, want, f);
    length += got;
    if (max_bytes && length > max_bytes) throw too_many_bytes(path, max_bytes);
    if (got && on_bytes) on_bytes(got);
    if (got == 0) break;
  }
  std::memset(s.bytes.get() + length, 0, simdjson::SIMDJSON_PADDING);
  return length;
}

/// What the top-level walk gathers before the city objects are converted.
struct TopLevel {
  Transform transform;
  Templates templates;
  std::vector<double> raw;  // vertices as written until "transform" is known (it may come after them)
  bool is_cityjson = false;
  bool has_objects = false;
};

/// One vertex as written: three numbers, else NaN (counted as bad later).
template <class Array>
void push_raw_vertex(Array coords, bool is_array, std::vector<double>& raw) {
  double xyz[3] = {NAN, NAN, NAN};
  std::size_t n = 0;
  bool ok = is_array;
  if (is_array) {
    for (auto c : coords) {
      double d = NAN;
      if (n < 3 && c.get_double().get(d) == simdjson::SUCCESS) xyz[n] = d;
      else ok = false;
      ++n;
    }
  }
  ok = ok && n == 3;
  raw.insert(raw.end(), {ok ? xyz[0] : NAN, xyz[1], xyz[2]});
}

void check_type(std::string_view type, const std::string& path) {
  if (type != "CityJSON")
    throw InputError(path + ": \"type\" is \"" + std::string(type.substr(0, 40)) +
                     "\", not \"CityJSON\" (a CityJSONFeature line belongs in a .city.jsonl sequence)");
}

/// Vertices with the transform applied; the top-level checks.
std::vector<Point3> finish_top(TopLevel& top, const std::string& path, std::vector<Problem>& problems, CityJsonInfo& info) {
  if (!top.is_cityjson) throw InputError(path + ": no \"type\": \"CityJSON\" at the top level; not a CityJSON file");
  if (!top.has_objects) throw InputError(path + ": no \"CityObjects\"; not a CityJSON file");
  std::vector<Point3> vertices;
  std::size_t bad_vertices = 0;
  vertices.reserve(top.raw.size() / 3);
  for (std::size_t i = 0; i + 2 < top.raw.size(); i += 3)
    cityjson::add_vertex(vertices, &top.raw[i],
                         std::isfinite(top.raw[i]) && std::isfinite(top.raw[i + 1]) && std::isfinite(top.raw[i + 2]),
                         top.transform, bad_vertices);
  std::vector<double>().swap(top.raw);
  info.vertices = vertices.size();
  note_bad_vertices(bad_vertices, "\"vertices\"", path, problems);
  return vertices;
}

/// The fast path: the whole file as one DOM, parsed by simdjson's runtime-dispatched kernel (icelake,
/// haswell ...; Debian's simdjson gives On-Demand only the portable one), each city object converted
/// from it with no second parse. Returns false, having read nothing, when the file is not valid JSON
/// (or nests deeper than max_depth): the object-by-object path then says which object is broken.
bool read_whole_dom(Scratch& scratch, std::size_t length, const std::string& path, const CityJsonOptions& options,
                    std::vector<Problem>& problems, CityJsonInfo& info, ObjectConverter& converter) {
  dom::parser& parser = scratch.whole;
  if (parser.capacity() < length || parser.max_depth() != options.max_depth) {
    const std::size_t capacity = std::max(length, parser.capacity());
    if (parser.allocate(capacity, options.max_depth) != simdjson::SUCCESS) return false;
    // Lower bounds of what allocate() took (simdjson 3.0.1: tape 8, strings 5/3, index 4 bytes a byte).
    prefer_huge_pages(parser.doc.tape.get(), 8 * capacity);
    prefer_huge_pages(parser.doc.string_buf.get(), capacity / 3 * 5);
    if (parser.implementation) prefer_huge_pages(parser.implementation->structural_indexes.get(), 4 * capacity);
  }
  dom::element root_el;
  if (parser.parse(scratch.bytes.get(), length, false).get(root_el) != simdjson::SUCCESS) return false;
  dom::object root;
  if (root_el.get_object().get(root) != simdjson::SUCCESS) return false;
  TopLevel top;
  std::vector<dom::array> vertex_arrays;  // "vertices" (once, in a valid file), read when "transform" is known
  std::uint64_t at_object = 0;
  try {
    for (dom::key_value_pair field : root) {
      const std::string_view key = field.key;
      if (key == "type") {
        check_type(field.value.get_string(), path);
        top.is_cityjson = true;
      } else if (key == "version") {
        info.version = std::string(std::string_view(field.value.get_string()).substr(0, 16));
      } else if (key == "transform") {
        field.value.get_object().value();  // as the On-Demand path: not an object is not CityJSON
        top.transform = cityjson::parse_transform(field.value, path);
      } else if (key == "metadata") {
        field.value.get_object().value();
        read_metadata(field.value, info);
      } else if (key == "geometry-templates") {
        field.value.get_object().value();
        top.templates = cityjson::parse_templates(field.value, path, problems);
      } else if (key == "vertices") {
        vertex_arrays.push_back(field.value.get_array());
      } else if (key == "CityObjects") {
        top.has_objects = true;
      }
    }
    finish_top(top, path, problems, info);  // the checks; no raw vertices on this path
    // Straight into the thread's vector (its pages stay mapped from one file to the next).
    std::vector<Point3>& vertices = scratch.vertices.points;
    vertices.clear();
    std::size_t n = 0, bad = 0;
    for (dom::array a : vertex_arrays) n += a.size();
    if (vertices.capacity() < n) {
      vertices.reserve(n);
      prefer_huge_pages(vertices.data(), n * sizeof(Point3));
    }
    for (dom::array a : vertex_arrays)
      for (dom::element v : a) {
        double xyz[3] = {NAN, NAN, NAN};
        dom::array coords;
        bool ok = v.get_array().get(coords) == simdjson::SUCCESS;
        std::size_t k = 0;
        if (ok)
          for (dom::element c : coords) {
            if (k >= 3 || c.get_double().get(xyz[k]) != simdjson::SUCCESS) ok = false;
            ++k;
          }
        cityjson::add_vertex(vertices, xyz, ok && k == 3, top.transform, bad);
      }
    info.vertices = vertices.size();
    note_bad_vertices(bad, "\"vertices\"", path, problems);
    scratch.vertices.classify(options.max_abs_coordinate);
    for (dom::key_value_pair field : root) {
      if (field.key != "CityObjects") continue;
      for (dom::key_value_pair object : field.value.get_object()) {
        ++at_object;
        object.value.get_object().value();  // as the On-Demand path: a city object that is no object ends the file
        converter.convert(object.key, object.value, scratch.vertices, top.templates);
      }
    }
  } catch (const simdjson::simdjson_error& e) {
    std::string where = at_object ? " (at city object " + std::to_string(at_object) + ")" : "";
    throw InputError(path + ": not valid CityJSON" + where + ": " + e.what());
  }
  return true;
}

/// The bytes of a CityJSONSeq file between two reads: the unfinished line at the front, the next chunk
/// behind it. Unlike std::string::resize, making room does not zero the bytes about to be read over
/// (a memset of every chunk was 3 % of reading a sequence).
class LineBuffer {
 public:
  std::size_t size() const { return size_; }
  const char* data() const { return bytes_.get(); }
  /// Drops the first n bytes.
  void erase_front(std::size_t n) {
    if (n < size_) std::memmove(bytes_.get(), bytes_.get() + n, size_ - n);
    size_ = n < size_ ? size_ - n : 0;
  }
  /// Appends up to n bytes read from f; returns how many came.
  std::size_t append_from(VSILFILE* f, std::size_t n) {
    if (capacity_ - size_ < n) {
      const std::size_t want = std::max(size_ + n, 2 * capacity_);
      std::unique_ptr<char[]> next(new char[want]);
      if (size_) std::memcpy(next.get(), bytes_.get(), size_);
      bytes_ = std::move(next);
      capacity_ = want;
    }
    const std::size_t got = VSIFReadL(bytes_.get() + size_, 1, n, f);
    size_ += got;
    return got;
  }
  /// The first `c` at or after `from`, else npos.
  std::size_t find(char c, std::size_t from) const {
    if (from >= size_) return std::string::npos;
    const void* hit = std::memchr(bytes_.get() + from, c, size_ - from);
    return hit ? static_cast<std::size_t>(static_cast<const char*>(hit) - bytes_.get()) : std::string::npos;
  }

 private:
  std::unique_ptr<char[]> bytes_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace

void read_cityjson(const std::string& path, const CityJsonOptions& options, const MeshCallback& on_mesh,
                   std::vector<Problem>& problems, CityJsonInfo& info) {
  info = CityJsonInfo{};
  ScratchLease scratch;
  const std::size_t length = load(path, options.max_bytes, options.on_bytes, *scratch);
  info.bytes = length;
  const simdjson::padded_string_view json(scratch->bytes.get(), length, scratch->capacity);
  ObjectConverter converter(path, options, on_mesh, problems, info);
  if (read_whole_dom(*scratch, length, path, options, problems, info, converter)) return;

  // Not valid JSON somewhere: On-Demand over the top level, each city object parsed on its own, so that
  // one broken object is a Problem naming it and the others are read.
  std::unique_ptr<dom::parser> meta_parser = make_dom_parser(options.max_depth);
  std::unique_ptr<dom::parser> template_parser = make_dom_parser(options.max_depth);
  TopLevel top;
  std::uint64_t at_object = 0;  // for messages: the city object being read
  try {
    ondemand::parser parser;
    ondemand::document doc = parser.iterate(json);
    ondemand::object root = doc.get_object();
    for (auto field : root) {
      const std::string_view key = field.unescaped_key();
      if (key == "type") {
        check_type(field.value().get_string(), path);
        top.is_cityjson = true;
      } else if (key == "version") {
        info.version = std::string(std::string_view(field.value().get_string()).substr(0, 16));
      } else if (key == "transform") {
        const std::string_view text = object_text(field.value());
        top.transform = cityjson::parse_transform(meta_parser->parse(text.data(), text.size(), false), path);
      } else if (key == "metadata") {
        const std::string_view text = object_text(field.value());
        read_metadata(meta_parser->parse(text.data(), text.size(), false), info);
      } else if (key == "geometry-templates") {
        const std::string_view text = object_text(field.value());
        top.templates = cityjson::parse_templates(template_parser->parse(text.data(), text.size(), false), path, problems);
      } else if (key == "vertices") {
        for (auto v : field.value().get_array()) {
          ondemand::array coords;
          const bool is_array = v.get_array().get(coords) == simdjson::SUCCESS;
          push_raw_vertex(coords, is_array, top.raw);
        }
      } else if (key == "CityObjects") {
        top.has_objects = true;  // second pass
      }
    }
    cityjson::VertexTable vertices;
    vertices.points = finish_top(top, path, problems, info);
    vertices.classify(options.max_abs_coordinate);

    // A second iteration rather than doc.rewind(): UBSan finds rewind() reading a null parser after some
    // malformed first passes (simdjson 3.0.1); the same parser keeps its buffers, only stage 1 runs again.
    doc = parser.iterate(json);
    std::unique_ptr<dom::parser> object_parser = make_dom_parser(options.max_depth);
    for (auto field : doc.get_object()) {
      const std::string_view key = field.unescaped_key();
      if (key != "CityObjects") continue;
      for (auto object : field.value().get_object()) {
        ++at_object;
        const std::string_view id = object.unescaped_key();
        const std::string_view text = object_text(object.value());
        dom::element element;
        if (const auto err = object_parser->parse(text.data(), text.size(), false).get(element)) {
          problems.push_back(Problem{std::string(id.substr(0, 256)), path, "read", "BAD_CITYOBJECT",
                                     std::string("city object is not valid JSON: ") + simdjson::error_message(err)});
          continue;
        }
        converter.convert(id, element, vertices, top.templates);
      }
    }
  } catch (const simdjson::simdjson_error& e) {
    std::string where = at_object ? " (at city object " + std::to_string(at_object) + ")" : "";
    throw InputError(path + ": not valid CityJSON" + where + ": " + e.what());
  }
}

void read_cityjson_seq(const std::string& path, const CityJsonOptions& options, const MeshCallback& on_mesh,
                       std::vector<Problem>& problems, CityJsonInfo& info) {
  info = CityJsonInfo{};
  info.sequence = true;
  VsiFile holder;
  VSILFILE* f = open_or_throw(path, holder);

  Transform transform;
  std::unique_ptr<dom::parser> header_parser = make_dom_parser(options.max_depth);  // keeps the templates alive
  std::unique_ptr<dom::parser> line_parser = make_dom_parser(options.max_depth);
  Templates templates;
  cityjson::VertexTable vertices;
  ObjectConverter converter(path, options, on_mesh, problems, info);
  bool have_header = false;

  // Line by line through one buffer: constant memory (the longest line, at most max_line_bytes).
  LineBuffer buf;
  std::size_t start = 0;      // first byte of the current line in buf
  std::size_t line_no = 0;
  bool skipping = false;      // inside a line that is too long: drop bytes up to its newline
  bool eof = false;
  constexpr std::size_t kChunk = 1 << 20;

  auto handle_line = [&](std::string_view line) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) return;
    // Built only for a message: a string per line cost as much as a tenth of the conversion.
    auto name = [&] { return path + " line " + std::to_string(line_no); };
    dom::element doc;
    // buf keeps simdjson::SIMDJSON_PADDING bytes after every line (see below), so no copy is needed.
    if (const auto err = line_parser->parse(line.data(), line.size(), false).get(doc)) {
      if (!have_header) throw InputError(name() + ": not valid JSON (" + simdjson::error_message(err) + ")");
      problems.push_back(Problem{"", path, "read", "BAD_LINE",
                                 "line " + std::to_string(line_no) + " is not valid JSON (" + simdjson::error_message(err) +
                                     "); its features are skipped"});
      return;
    }
    // The members used, in one pass over the line's fields (each lookup by key scans them); the first of
    // a repeated key, as a lookup finds.
    dom::element type_el, vertices_el, objects_el, id_el;
    bool has_type = false, has_vertices = false, has_objects = false, has_id = false;
    dom::object top;
    if (doc.get_object().get(top) == simdjson::SUCCESS) {
      for (dom::key_value_pair field : top) {
        const std::string_view key = field.key;
        if (key == "type") {
          if (!has_type) type_el = field.value, has_type = true;
        } else if (key == "vertices") {
          if (!has_vertices) vertices_el = field.value, has_vertices = true;
        } else if (key == "CityObjects") {
          if (!has_objects) objects_el = field.value, has_objects = true;
        } else if (key == "id") {
          if (!has_id) id_el = field.value, has_id = true;
        }
      }
    }
    std::string_view type;
    if (!has_type || type_el.get_string().get(type) != simdjson::SUCCESS) type = {};
    if (!have_header) {
      if (type != "CityJSON")
        throw InputError(name() + ": the first line of a CityJSONSeq file must be the \"CityJSON\" header (transform, "
                                "CRS), not \"" + std::string(type.substr(0, 40)) + "\"");
      // The header is parsed again by its own parser, which lives as long as the templates.
      dom::element header = header_parser->parse(line.data(), line.size(), false);
      std::string_view version;
      if (header["version"].get_string().get(version) == simdjson::SUCCESS) info.version = std::string(version.substr(0, 16));
      dom::element e;
      if (header["transform"].get(e) == simdjson::SUCCESS) transform = cityjson::parse_transform(e, path);
      if (header["metadata"].get(e) == simdjson::SUCCESS) read_metadata(e, info);
      if (header["geometry-templates"].get(e) == simdjson::SUCCESS)
        templates = cityjson::parse_templates(e, path, problems);
      have_header = true;
      return;
    }
    if (type != "CityJSONFeature") {
      problems.push_back(Problem{"", path, "read", "BAD_LINE",
                                 "line " + std::to_string(line_no) + " is not a CityJSONFeature (\"type\": \"" +
                                     std::string(type.substr(0, 40)) + "\"); skipped"});
      return;
    }
    ++info.features;
    dom::array verts;
    dom::object objects;
    if (!has_vertices || vertices_el.get_array().get(verts) != simdjson::SUCCESS || !has_objects ||
        objects_el.get_object().get(objects) != simdjson::SUCCESS) {
      std::string_view fid;
      if (!has_id || id_el.get_string().get(fid) != simdjson::SUCCESS) fid = {};
      problems.push_back(Problem{std::string(fid.substr(0, 256)), path, "read", "BAD_LINE",
                                 "line " + std::to_string(line_no) +
                                     ": a CityJSONFeature needs \"CityObjects\" and \"vertices\"; skipped"});
      return;
    }
    std::size_t bad = 0;
    read_vertices(verts, transform, vertices.points, bad);
    vertices.classify(options.max_abs_coordinate);
    info.vertices += vertices.points.size();
    if (bad) note_bad_vertices(bad, "line " + std::to_string(line_no) + " \"vertices\"", path, problems);
    for (auto [id, object] : objects) converter.convert(id, object, vertices, templates);
  };

  auto too_long = [&] {
    ++line_no;
    if (!have_header) throw InputError(path + ": the first line is longer than " + std::to_string(options.max_line_bytes) + " bytes");
    problems.push_back(Problem{"", path, "read", "LINE_TOO_LONG",
                               "line " + std::to_string(line_no) + " is longer than " +
                                   std::to_string(options.max_line_bytes) + " bytes (max_line_bytes); skipped"});
  };

  while (!eof) {
    // Keep the unfinished line at the front, then read the next chunk behind it.
    if (start > 0) {
      buf.erase_front(start);
      start = 0;
    }
    const std::size_t at = buf.size();
    const std::size_t got = buf.append_from(f, kChunk);
    info.bytes += got;
    if (options.max_bytes && info.bytes > options.max_bytes) throw too_many_bytes(path, options.max_bytes);
    if (got && options.on_bytes) options.on_bytes(got);
    eof = got < kChunk;
    std::size_t scan = at;
    for (;;) {
      const std::size_t nl = buf.find('\n', scan);
      if (nl == std::string::npos) break;
      if (skipping) {
        skipping = false;
      } else {
        // Parse [start, nl) in place when the simdjson::SIMDJSON_PADDING bytes simdjson may read past its end
        // lie inside buf; near the end of buf, a padded copy.
        const std::size_t len = nl - start;
        const std::string_view line(buf.data() + start, len);
        std::string tail;
        if (len > options.max_line_bytes) {
          too_long();
        } else if (buf.size() - nl < simdjson::SIMDJSON_PADDING) {
          tail.assign(line);
          tail.resize(len + simdjson::SIMDJSON_PADDING, '\0');
          handle_line(std::string_view(tail.data(), len));
        } else {
          handle_line(line);
        }
      }
      start = nl + 1;
      scan = start;
    }
    if (buf.size() - start > options.max_line_bytes) {
      if (!skipping) too_long();
      skipping = true;
      start = buf.size();
    }
  }
  if (!skipping && start < buf.size() && buf.size() - start > options.max_line_bytes) {
    too_long();
  } else if (!skipping && start < buf.size()) {
    std::string last(buf.data() + start, buf.size() - start);
    const std::size_t len = last.size();
    last.resize(len + simdjson::SIMDJSON_PADDING, '\0');
    handle_line(std::string_view(last.data(), len));
  }
  if (!have_header) throw InputError(path + ": empty; a CityJSONSeq file starts with a \"CityJSON\" header line");
}

}  // namespace groundplan::gis
