// SPDX-License-Identifier: MIT
#pragma once
// Hardened expat for the KML and COLLADA readers (issue 6): the same rules as the CityGML reader
// (gis/src/citygml/citygml_reader.cpp): no DTD loading, no parameter entities, any entity
// declaration stops the parse (billion laughs, XXE), a nesting-depth limit. Namespace mode: a name
// arrives as "URI local" and is handed over split, so prefixes never matter.
//
// Also the bounded byte source the KMZ reader needs (zip bombs): every byte read through
// parse_vsi_file() counts against a ByteBudget, checked before (the stated size) and while reading.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>

struct XML_ParserStruct;

namespace groundplan::gis::xml {

/// What a document may cost in unpacked bytes. One budget is shared by every file of one input
/// (a KMZ's doc.kml and all its .dae entries).
struct ByteBudget {
  std::uint64_t max_entry_bytes = std::uint64_t{256} << 20;  // one file / archive entry
  std::uint64_t max_total_bytes = std::uint64_t{1} << 30;    // all of them together
  std::uint64_t used = 0;
};

class Handler {
 public:
  virtual ~Handler() = default;
  /// `atts`: expat's null-terminated name/value array; names are "local" or "URI local".
  virtual void start(std::string_view uri, std::string_view local, const char** atts) = 0;
  virtual void end(std::string_view uri, std::string_view local) = 0;
  /// Character data, only while capture is on (SafeParser::capture_text).
  virtual void text(std::string_view chunk) {}
};

class SafeParser {
 public:
  /// `name` names the document in messages. Throws Error when expat cannot be created.
  SafeParser(std::string name, Handler& handler, std::size_t max_depth = 256);
  ~SafeParser();
  SafeParser(const SafeParser&) = delete;
  SafeParser& operator=(const SafeParser&) = delete;

  /// Feeds one chunk (`last` on the final one, which may be empty). Throws InputError naming the
  /// document for malformed or hostile XML; exceptions thrown by the handler propagate.
  void feed(const char* data, std::size_t n, bool last);
  /// Turns Handler::text on or off (off by default: whitespace between elements costs nothing).
  void capture_text(bool on) { capture_ = on; }
  /// Stops the parse with an InputError carrying `reason` (from inside a handler).
  void stop(std::string reason);
  std::size_t line() const;
  std::size_t depth() const { return depth_; }
  const std::string& name() const { return name_; }

 private:
  static void on_start(void* ud, const char* name, const char** atts);
  static void on_end(void* ud, const char* name);
  static void on_text(void* ud, const char* s, int len);
  static void on_entity_decl(void* ud, const char* name, int, const char*, int, const char*, const char*,
                             const char*, const char*);
  static void on_unparsed_entity_decl(void* ud, const char* name, const char*, const char*, const char*,
                                      const char*);

  std::string name_;
  Handler& handler_;
  std::size_t max_depth_;
  std::size_t depth_ = 0;
  bool capture_ = false;
  XML_ParserStruct* parser_ = nullptr;
  std::string stop_reason_;
  std::exception_ptr pending_;
};

/// The value of attribute `local` (any namespace), or nullptr.
const char* attribute(const char** atts, std::string_view local);

/// Streams the VSI file `path` through `parser`, counting bytes against `budget`: the file's stated
/// size is checked first, the bytes actually read as they come (a forged size does not help).
/// Throws InputError naming `display_name` when the file cannot be opened or a limit is passed.
void parse_vsi_file(const std::string& path, const std::string& display_name, SafeParser& parser, ByteBudget& budget);

/// Reads a whole VSI file into memory under the same budget rules.
std::string read_vsi_file(const std::string& path, const std::string& display_name, ByteBudget& budget);

}  // namespace groundplan::gis::xml
