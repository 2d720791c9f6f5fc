// SPDX-License-Identifier: MIT
#pragma once
// The CityGML reader's fast path (issue 14): a document held in memory (a file of a few MiB, one chunk
// of a large file) is parsed by pugixml into a tree, 4-5x faster than expat's callbacks, and the tree is
// walked handing out exactly the events expat gives in namespace mode: element names as "URI local"
// (separator ' '), attributes in document order without the xmlns declarations, character data,
// end tags, and for every event the line expat would say.
//
// pugixml accepts some documents that expat refuses (entity references it does not know, a DOCTYPE's
// internal subset, bytes that are not UTF-8, junk after the root, duplicate attributes, unbound
// prefixes, a malformed declaration, names expat refuses ...) or reads them otherwise (the whitespace
// between elements inside a text element). Such a document is refused by load() before any event,
// with the reason (fuzz_citygml checks that both read every other document alike); the caller
// then hands the same bytes to expat, which reports the problem exactly as before. Entities are never
// expanded here (a DOCTYPE is refused), so entity bombs and external entities stay expat's business,
// where they are refused too (citygml_reader.cpp).
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace groundplan::gis::xml {

class DomEvents {
 public:
  /// Receives the events of walk(); names and attributes as expat's XML_ParserCreateNS(' ') gives them.
  class Sink {
   public:
    virtual ~Sink() = default;
    virtual void start(const char* name, const char** atts) = 0;
    virtual void end() = 0;
    virtual bool wants_text() const = 0;  // text() is called only while this holds
    virtual void text(const char* s, std::size_t n) = 0;
    virtual bool stopped() const = 0;  // checked after every event: true ends the walk
  };

  DomEvents();
  ~DomEvents();
  DomEvents(const DomEvents&) = delete;
  DomEvents& operator=(const DomEvents&) = delete;

  /// Parses [data, data + n), which is not modified and must outlive this object. Returns "" when the
  /// document can be walked, otherwise why it is left to expat.
  std::string load(const char* data, std::size_t n);
  /// Hands every event of the loaded document to `sink`, in document order, until sink.stopped().
  /// Exceptions thrown by the sink propagate.
  void walk(Sink& sink);
  /// The line of the event being handed out, counted as expat counts (LF, CR LF and CR each end a
  /// line): a start tag's '<'; an end tag's "</", or the '<' of an empty-element tag.
  std::size_t line() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Why `data` is not plain UTF-8 XML text that pugixml reads as expat does: a byte sequence that is not
/// UTF-8, a character XML forbids, or an entity reference other than the five predefined ones and
/// character references. "" when none. (Exposed for its test.)
std::string check_xml_text(std::string_view data);

}  // namespace groundplan::gis::xml
