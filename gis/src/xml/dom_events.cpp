// SPDX-License-Identifier: MIT
#include "xml/dom_events.h"
#include "xml/block_cache.h"

#include <pugixml.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace groundplan::gis::xml {
namespace {

constexpr std::string_view kXmlNs = "http://www.w3.org/XML/1998/namespace";
constexpr std::size_t kMaxAttributes = 64;  // past this the duplicate check is expat's (a hash, not pairs)

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool starts_with(std::string_view d, std::size_t at, std::string_view s) {
  return d.size() - std::min(at, d.size()) >= s.size() && d.compare(at, s.size(), s) == 0;
}

/// XML 1.0's Char production.
bool xml_char(std::uint32_t c) {
  return c == 0x9 || c == 0xA || c == 0xD || (c >= 0x20 && c <= 0xD7FF) || (c >= 0xE000 && c <= 0xFFFD) ||
         (c >= 0x10000 && c <= 0x10FFFF);
}

/// The reference at d[at] == '&' when it is one pugixml resolves as expat does; its length, or 0.
std::size_t reference_length(std::string_view d, std::size_t at) {
  const std::size_t end = d.find(';', at);
  if (end == std::string_view::npos || end - at > 12) return 0;
  const std::string_view name = d.substr(at + 1, end - at - 1);
  if (name == "amp" || name == "lt" || name == "gt" || name == "quot" || name == "apos") return end - at + 1;
  if (name.size() < 2 || name[0] != '#') return 0;
  const bool hex = name[1] == 'x';
  if (hex && name.size() < 3) return 0;
  std::uint32_t v = 0;
  for (std::size_t k = hex ? 2 : 1; k < name.size(); ++k) {
    const char c = name[k];
    std::uint32_t digit;
    if (c >= '0' && c <= '9') digit = static_cast<std::uint32_t>(c - '0');
    else if (hex && c >= 'a' && c <= 'f') digit = static_cast<std::uint32_t>(c - 'a' + 10);
    else if (hex && c >= 'A' && c <= 'F') digit = static_cast<std::uint32_t>(c - 'A' + 10);
    else return 0;
    v = v * (hex ? 16 : 10) + digit;
    if (v > 0x10FFFF) return 0;
  }
  return xml_char(v) ? end - at + 1 : 0;
}

/// The UTF-8 sequence at d[at] (a lead byte >= 0x80): its length when it is well formed and an XML
/// character, or 0.
std::size_t utf8_length(std::string_view d, std::size_t at) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(d[at + k]); };
  const unsigned char c = b(0);
  std::size_t len;
  std::uint32_t v;
  if (c >= 0xC2 && c <= 0xDF) len = 2, v = c & 0x1F;
  else if (c >= 0xE0 && c <= 0xEF) len = 3, v = c & 0x0F;
  else if (c >= 0xF0 && c <= 0xF4) len = 4, v = c & 0x07;
  else return 0;
  if (d.size() - at < len) return 0;
  for (std::size_t k = 1; k < len; ++k) {
    if ((b(k) & 0xC0) != 0x80) return 0;
    v = (v << 6) | (b(k) & 0x3F);
  }
  const std::uint32_t min = len == 2 ? 0x80 : len == 3 ? 0x800 : 0x10000;
  if (v < min || (v >= 0xD800 && v <= 0xDFFF) || !xml_char(v)) return 0;
  return len;
}

/// A prefix of up to 8 bytes packed into an integer (longer ones: 0, compared as strings).
std::uint64_t pack(std::string_view prefix) {
  std::uint64_t k = 0;
  if (!prefix.empty() && prefix.size() <= 8) std::memcpy(&k, prefix.data(), prefix.size());  // data() may be null
  return k;
}

/// A binding of a namespace prefix in force; `expanded` is "URI " (what precedes a local name).
struct Binding {
  std::string_view prefix;
  std::string_view uri;
  std::string expanded;
  std::uint64_t key = pack(prefix);
};

/// An element or attribute name of ASCII name characters only, not starting with a digit, '-' or '.':
/// the names expat and pugixml both read alike (pugixml takes any byte >= 0x80 as a name character, expat
/// only those Unicode allows).
/// Which bytes plain_name takes: 1 anywhere in a name, 2 also first.
constexpr std::array<std::uint8_t, 256> kNameBytes = [] {
  std::array<std::uint8_t, 256> t{};
  for (int c = 0; c < 256; ++c) {
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == ':';
    const bool other = (c >= '0' && c <= '9') || c == '-' || c == '.';
    t[static_cast<std::size_t>(c)] = letter ? 3 : other ? 1 : 0;
  }
  return t;
}();

bool plain_name(const char* name) {
  // A table, not a chain of comparisons: the checks call this for every element and attribute name.
  const auto* p = reinterpret_cast<const unsigned char*>(name);
  if (!(kNameBytes[*p] & 2)) return false;  // also the empty name (byte 0)
  for (++p; *p; ++p)
    if (!kNameBytes[*p]) return false;
  return true;
}

/// "p:local" -> where the colon is, or nullptr.
const char* colon_of(const char* name);

/// In one pass, what check_element asks of an element or attribute name: a plain name whose colon, if any, is
/// the only one and splits it into a non-empty prefix and a local part that is a plain name itself. `colon`:
/// where the colon is, or nullptr.
bool plain_qualified_name(const char* name, const char*& colon) {
  const auto* p = reinterpret_cast<const unsigned char*>(name);
  colon = nullptr;
  if (!(kNameBytes[*p] & 2) || *p == ':') return false;  // also the empty name; ":x" has an empty prefix
  for (++p; *p; ++p) {
    if (*p != ':') {
      if (!kNameBytes[*p]) return false;
      continue;
    }
    if (colon || !(kNameBytes[p[1]] & 2) || p[1] == ':') return false;  // a second colon, or a bad local start
    colon = reinterpret_cast<const char*>(p);
  }
  return true;
}

/// Why expat would refuse a comment or a processing instruction that pugixml read: "--" inside a comment
/// or "-" at its end; a PI target named xml in any case, or one that is not a plain name.
std::string misc_problem(pugi::xml_node n) {
  const char* v = n.value();
  if (n.type() == pugi::node_comment) {
    const std::size_t len = std::strlen(v);
    if (std::strstr(v, "--") || (len && v[len - 1] == '-')) return "\"--\" in a comment";
    return "";
  }
  const char* t = n.name();
  if (!plain_name(t) || colon_of(t)) return "a processing instruction named \"" + std::string(t) + "\"";
  if (std::strlen(t) == 3 && (t[0] | 0x20) == 'x' && (t[1] | 0x20) == 'm' && (t[2] | 0x20) == 'l')
    return "a processing instruction named \"" + std::string(t) + "\"";
  return "";
}

/// "p:local" -> where the colon is, or nullptr.
const char* colon_of(const char* name) {
  for (; *name; ++name)
    if (*name == ':') return name;
  return nullptr;
}

/// The inside of an XML declaration (between "<?xml" and "?>"): "" when it is XMLDecl's grammar with
/// version 1.x, an encoding of UTF-8 or US-ASCII if any, standalone yes or no if any; else why not.
std::string check_declaration(std::string_view decl) {
  std::size_t q = 0;
  const auto spaces = [&] {
    const std::size_t at = q;
    while (q < decl.size() && is_space(decl[q])) ++q;
    return q > at;
  };
  // at least one space, then name Eq quoted-value: the value; false when malformed
  const auto pseudo = [&](std::string_view name, std::string& value) {
    if (!spaces() || decl.compare(q, name.size(), name) != 0) return false;
    q += name.size();
    spaces();
    if (q >= decl.size() || decl[q] != '=') return false;
    ++q;
    spaces();
    if (q >= decl.size() || (decl[q] != '"' && decl[q] != '\'')) return false;
    const std::size_t close = decl.find(decl[q], q + 1);
    if (close == std::string_view::npos) return false;
    value = std::string(decl.substr(q + 1, close - q - 1));
    q = close + 1;
    return true;
  };
  std::string version, encoding, standalone;
  if (!pseudo("version", version) || version.size() < 3 || version.compare(0, 2, "1.") != 0 ||
      version.find_first_not_of("0123456789", 2) != std::string::npos)
    return "an XML declaration without a version 1.x";
  std::size_t mark = q;
  if (pseudo("encoding", encoding)) {
    for (char& c : encoding) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    if (encoding != "utf-8" && encoding != "us-ascii") return "the encoding \"" + encoding + "\"";
    mark = q;
  } else {
    q = mark;
  }
  if (pseudo("standalone", standalone)) {
    if (standalone != "yes" && standalone != "no") return "an XML declaration with standalone=\"" + standalone + "\"";
  } else {
    q = mark;
  }
  spaces();
  return q == decl.size() ? "" : "an XML declaration expat would not read";
}

}  // namespace

std::string check_xml_text(std::string_view d) {
  constexpr std::uint64_t kOnes = 0x0101010101010101ull, kHigh = 0x8080808080808080ull;
  std::size_t i = 0;
  while (i < d.size()) {
#if defined(__SSE2__)
    // Sixteen bytes at once: none >= 0x80, none < 0x20 but tab, LF and CR, no '&'.
    while (d.size() - i >= 16) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(d.data() + i));
      __m128i bad = _mm_cmplt_epi8(v, _mm_set1_epi8(0x20));  // signed: also every byte >= 0x80
      bad = _mm_andnot_si128(_mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(v, _mm_set1_epi8('\t')),
                                                       _mm_cmpeq_epi8(v, _mm_set1_epi8('\n'))),
                                          _mm_cmpeq_epi8(v, _mm_set1_epi8('\r'))),
                             bad);
      bad = _mm_or_si128(bad, _mm_cmpeq_epi8(v, _mm_set1_epi8('&')));
      const int mask = _mm_movemask_epi8(bad);
      if (mask) {
        i += static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(mask)));
        break;
      }
      i += 16;
    }
    if (i >= d.size()) break;
#endif
    if (d.size() - i >= 8) {  // eight plain ASCII characters at once: no byte >= 0x80, < 0x20 or '&'
      std::uint64_t w;
      std::memcpy(&w, d.data() + i, 8);
      const std::uint64_t amp = w ^ (kOnes * '&');
      const std::uint64_t flags = (((w - kOnes * 0x20) & ~w) | ((amp - kOnes) & ~amp) | w) & kHigh;
      if (!flags) {
        i += 8;
        continue;
      }
      // The lowest flagged byte is exact (borrows only run upwards): the bytes below it are plain.
      const std::size_t plain = static_cast<std::size_t>(__builtin_ctzll(flags)) / 8;
      if (plain) {
        i += plain;
        continue;
      }
    }
    const unsigned char c = static_cast<unsigned char>(d[i]);
    if (c < 0x20) {
      if (c != '\t' && c != '\n' && c != '\r')
        return "the control character " + std::to_string(c) + " at byte " + std::to_string(i);
      ++i;
    } else if (c == '&') {
      const std::size_t n = reference_length(d, i);
      if (!n) return "an entity or character reference pugixml would read otherwise at byte " + std::to_string(i);
      i += n;
    } else if (c < 0x80) {
      ++i;
    } else {
      const std::size_t n = utf8_length(d, i);
      if (!n) return "bytes that are not UTF-8 XML characters at byte " + std::to_string(i);
      i += n;
    }
  }
  return "";
}

struct DomEvents::Impl {
  std::string_view data;
  pugi::xml_document doc;
  std::vector<Binding> bindings;
  std::vector<std::size_t> marks;  // bindings.size() when each open element started
  std::string name;
  std::vector<std::string> attr_names;
  std::vector<const char*> atts;
  pugi::xml_node current;
  bool at_end = false;
  mutable std::size_t line_offset = 0, line_number = 1;

  // ---- namespaces ----
  static bool is_declaration(const char* a) {
    return a[0] == 'x' && a[1] == 'm' && a[2] == 'l' && a[3] == 'n' && a[4] == 's' && (a[5] == 0 || a[5] == ':');
  }
  const Binding* find(std::string_view prefix) const {
    const std::uint64_t key = pack(prefix);
    for (std::size_t k = bindings.size(); k-- > 0;) {
      const Binding& b = bindings[k];
      if (b.key == key && b.prefix.size() == prefix.size() && (prefix.size() <= 8 || b.prefix == prefix)) return &b;
    }
    return nullptr;
  }
  /// Pushes the element's declarations; "" or why expat would refuse them. `names`: also the "URI " strings
  /// that element names are built from (only the walk that hands out events needs them).
  std::string open_scope(pugi::xml_node n, bool names) {
    marks.push_back(bindings.size());
    for (pugi::xml_attribute a = n.first_attribute(); a; a = a.next_attribute()) {
      const char* an = a.name();
      if (!is_declaration(an)) continue;
      const std::string_view prefix = an[5] ? std::string_view(an + 6) : std::string_view();
      const std::string_view uri = a.value();
      if (an[5] && (prefix.empty() || uri.empty() || prefix == "xml" || prefix == "xmlns" || colon_of(prefix.data()) ||
                    !plain_name(prefix.data())))
        return "the namespace declaration " + std::string(an);
      if (uri == kXmlNs) return "a declaration of the XML namespace";
      if (uri.find(' ') != std::string_view::npos) return "a namespace URI with a space";  // expat's separator
      for (std::size_t k = marks.back(); k < bindings.size(); ++k)
        if (bindings[k].prefix == prefix) return "the namespace declaration " + std::string(an) + " twice";
      Binding b{prefix, uri, std::string()};
      if (names && !uri.empty()) b.expanded.append(uri).push_back(' ');
      bindings.push_back(std::move(b));
    }
    return "";
  }
  void close_scope() {
    bindings.resize(marks.back());
    marks.pop_back();
  }
  /// "p:local" -> the binding of p (nullptr when unbound) and local; "local" -> the default binding.
  const Binding* resolve(const char* qname, bool attribute, const char*& local, bool& prefixed) const {
    const char* colon = colon_of(qname);
    prefixed = colon != nullptr;
    if (!colon) {
      local = qname;
      return attribute ? nullptr : find(std::string_view());
    }
    local = colon + 1;
    return find(std::string_view(qname, static_cast<std::size_t>(colon - qname)));
  }

  // ---- checks before any event ----
  /// Elements whose text the CityGML reader keeps. Holding elements, they would read otherwise: pugixml
  /// drops the whitespace between child elements that expat hands over as text.
  static bool text_element(std::string_view local) {
    return local == "posList" || local == "pos" || local == "coordinates" || local == "name" ||
           local == "measuredHeight" || local == "lowerCorner" || local == "upperCorner";
  }
  static bool holds_elements(pugi::xml_node n) {
    for (pugi::xml_node c = n.first_child(); c; c = c.next_sibling())
      if (c.type() == pugi::node_element) return true;
    return false;
  }
  std::string check_element(pugi::xml_node n) {
    const char* qname = n.name();
    const char* colon;
    if (!plain_qualified_name(qname, colon)) return "the element name \"" + std::string(qname) + "\"";
    const bool prefixed = colon != nullptr;
    const char* local = prefixed ? colon + 1 : qname;
    if (prefixed && !find(std::string_view(qname, static_cast<std::size_t>(colon - qname))))
      return "the unbound prefix of \"" + std::string(qname) + "\"";
    if (text_element(local) && holds_elements(n))
      return "the text element \"" + std::string(qname) + "\" holding elements";
    std::size_t count = 0;
    for (pugi::xml_attribute a = n.first_attribute(); a; a = a.next_attribute()) {
      if (++count > kMaxAttributes) return "an element with more than " + std::to_string(kMaxAttributes) + " attributes";
      const char* an = a.name();
      const char* acolon;
      const bool shaped = plain_qualified_name(an, acolon);
      if (!shaped && !plain_name(an)) return "the attribute name \"" + std::string(an) + "\"";
      if (std::strchr(a.value(), '<')) return "a '<' in the value of \"" + std::string(an) + "\"";  // or &lt;: expat's
      if (is_declaration(an)) continue;
      if (!shaped) return "the attribute name \"" + std::string(an) + "\"";
      const bool ap = acolon != nullptr;
      const char* al = ap ? acolon + 1 : an;
      const Binding* ab = ap ? find(std::string_view(an, static_cast<std::size_t>(acolon - an))) : nullptr;
      if (ap && !ab) return "the unbound prefix of \"" + std::string(an) + "\"";
      // duplicates, by (namespace, local name) as expat compares them
      const std::string_view uri = ap ? ab->uri : std::string_view();
      for (pugi::xml_attribute o = n.first_attribute(); count > 1 && o != a; o = o.next_attribute()) {
        const char* on = o.name();
        if (is_declaration(on)) continue;
        const char* ol;
        bool op;
        const Binding* ob = resolve(on, true, ol, op);
        const std::string_view ouri = op && ob ? ob->uri : std::string_view();
        if (std::strcmp(ol, al) == 0 && ouri == uri) return "the duplicate attribute \"" + std::string(an) + "\"";
      }
    }
    return "";
  }

  // ---- positions in the source bytes (for line numbers) ----
  std::size_t skip_misc(std::size_t p) const {
    for (;;) {
      while (p < data.size() && is_space(data[p])) ++p;
      if (starts_with(data, p, "<!--")) {
        const std::size_t e = data.find("-->", p + 4);
        p = e == std::string_view::npos ? data.size() : e + 3;
      } else if (starts_with(data, p, "<?")) {
        const std::size_t e = data.find("?>", p + 2);
        p = e == std::string_view::npos ? data.size() : e + 2;
      } else {
        return p;
      }
    }
  }
  /// Just past the '>' of `n`'s start tag; `empty`: it is an empty-element tag.
  std::size_t start_tag_end(pugi::xml_node n, bool& empty) const {
    std::size_t p = static_cast<std::size_t>(n.offset_debug());
    while (p < data.size() && data[p] != '>') {
      if (data[p] == '"' || data[p] == '\'') {
        const std::size_t q = data.find(data[p], p + 1);
        p = q == std::string_view::npos ? data.size() : q;
      }
      ++p;
    }
    empty = p > 0 && p < data.size() && data[p - 1] == '/';
    return std::min(p + 1, data.size());
  }
  /// Just past the last byte of a text, CDATA, comment or PI node.
  std::size_t text_end(pugi::xml_node n) const {
    const auto at = static_cast<std::size_t>(n.offset_debug());
    const char* close = n.type() == pugi::node_cdata ? "]]>" : n.type() == pugi::node_comment ? "-->"
                        : n.type() == pugi::node_pi ? "?>" : nullptr;
    if (close) {
      const std::size_t e = data.find(close, at);
      return e == std::string_view::npos ? data.size() : e + std::strlen(close);
    }
    const std::size_t e = data.find('<', at);
    return e == std::string_view::npos ? data.size() : e;
  }
  /// Where expat reports `e`'s end: its end tag's "</", or its empty-element tag's '<'. Walks down the
  /// last children, then back up (no recursion: the depth is the document's).
  std::size_t end_event_offset(pugi::xml_node e) const {
    bool empty;
    std::size_t after = start_tag_end(e, empty);
    if (empty) return static_cast<std::size_t>(e.offset_debug()) - 1;
    pugi::xml_node deepest = e;
    while (pugi::xml_node last = deepest.last_child()) {
      if (last.type() != pugi::node_element) {
        after = text_end(last);
        break;
      }
      deepest = last;
      bool last_empty;
      after = start_tag_end(deepest, last_empty);
      if (last_empty) break;
    }
    // `after` is just past the deepest last thing; climb to `e`, passing each end tag.
    for (pugi::xml_node n = deepest; n != e; n = n.parent()) {
      bool n_empty;
      if (n.first_child() || (start_tag_end(n, n_empty), !n_empty)) {
        const std::size_t close = data.find('>', skip_misc(after));
        after = close == std::string_view::npos ? data.size() : close + 1;
      }
    }
    return skip_misc(after);
  }
  std::size_t line_at(std::size_t off) const {
    if (off < line_offset) line_offset = 0, line_number = 1;
    for (std::size_t p = line_offset; p < off && p < data.size(); ++p) {
      if (data[p] == '\r' || (data[p] == '\n' && (p == 0 || data[p - 1] != '\r'))) ++line_number;
    }
    line_offset = off;
    return line_number;
  }

  // ---- the walk ----
  template <class OnStart, class OnText, class OnEnd>
  bool traverse(OnStart&& on_start, OnText&& on_text, OnEnd&& on_end) {
    const pugi::xml_node root = doc.document_element();
    pugi::xml_node n = root;
    for (;;) {
      if (n.type() == pugi::node_element) {
        if (!on_start(n)) return false;
        if (pugi::xml_node c = n.first_child()) {
          n = c;
          continue;
        }
        if (!on_end(n)) return false;
      } else if (n.type() != pugi::node_null) {  // text, CDATA, a comment or a PI
        if (!on_text(n)) return false;
      }
      for (;;) {
        if (n == root) return true;
        if (pugi::xml_node s = n.next_sibling()) {
          n = s;
          break;
        }
        n = n.parent();
        if (!on_end(n)) return false;
      }
    }
  }
};

DomEvents::DomEvents() {
  use_block_cache_for_pugixml();  // before the first document allocates
  impl_ = std::make_unique<Impl>();
}
DomEvents::~DomEvents() = default;

std::string DomEvents::load(const char* bytes, std::size_t n) {
  Impl& m = *impl_;
  m.data = std::string_view(bytes, n);
  const std::string_view d = m.data;
  // The prolog: an optional BOM and declaration (UTF-8 only), comments and PIs; no DOCTYPE.
  std::size_t p = 0;
  if (starts_with(d, 0, "\xEF\xBB\xBF")) p = 3;
  const bool declared = starts_with(d, p, "<?xml") && d.size() > p + 5 && (is_space(d[p + 5]) || d[p + 5] == '?');
  if (declared) {
    const std::size_t end = d.find("?>", p);
    if (end == std::string_view::npos) return "an unclosed XML declaration";
    if (std::string why = check_declaration(d.substr(p + 5, end - p - 5)); !why.empty()) return why;
    p = end + 2;
  }
  p = m.skip_misc(p);
  if (starts_with(d, p, "<!")) return "a DOCTYPE or other markup declaration before the root";
  if (p >= d.size() || d[p] != '<') return "no root element where the prolog ends";
  if (std::string why = check_xml_text(d); !why.empty()) return why;

  // parse_declaration: pugixml then refuses "<?xml" inside an element (it takes it for a PI otherwise).
  // parse_comments, parse_pi: kept as nodes, so that the checks below see them as expat does.
  const unsigned flags = pugi::parse_default | pugi::parse_ws_pcdata_single | pugi::parse_declaration |
                         pugi::parse_comments | pugi::parse_pi;
  const pugi::xml_parse_result r = m.doc.load_buffer(bytes, n, flags, pugi::encoding_utf8);
  if (!r) return std::string("pugixml: ") + r.description() + " at byte " + std::to_string(r.offset);
  std::size_t roots = 0;
  for (pugi::xml_node c = m.doc.first_child(); c; c = c.next_sibling()) {
    if (c.type() == pugi::node_comment || c.type() == pugi::node_pi)
      if (std::string why = misc_problem(c); !why.empty()) return why;
    if (c.type() == pugi::node_declaration && (!declared || c != m.doc.first_child()))
      return "an XML declaration past the start";
    if (c.type() != pugi::node_comment && c.type() != pugi::node_pi && c.type() != pugi::node_declaration) ++roots;
  }
  if (roots != 1 || !m.doc.document_element()) return "not exactly one root element";
  const pugi::xml_node root = m.doc.document_element();
  const std::size_t root_end = m.end_event_offset(root);
  bool empty;
  std::size_t after = root_end;
  if (m.start_tag_end(root, empty), !empty) {
    const std::size_t close = d.find('>', root_end);
    after = close == std::string_view::npos ? d.size() : close + 1;
  } else {
    after = m.start_tag_end(root, empty);
  }
  if (m.skip_misc(after) != d.size()) return "content after the root element";

  // Namespaces and attributes as expat in namespace mode checks them, before any event.
  std::string why;
  m.bindings.clear();
  m.bindings.push_back(Binding{"xml", kXmlNs, std::string(kXmlNs) + ' '});
  m.marks.clear();
  m.traverse(
      [&](pugi::xml_node e) {
        why = m.open_scope(e, false);
        if (why.empty()) why = m.check_element(e);
        return why.empty();
      },
      [&](pugi::xml_node t) {  // "]]>" outside CDATA: an error for expat, text for pugixml
        if (t.type() == pugi::node_comment || t.type() == pugi::node_pi) {
          why = misc_problem(t);
          return why.empty();
        }
        if (t.type() == pugi::node_pcdata)
          for (const char* v = std::strchr(t.value(), ']'); v; v = std::strchr(v + 1, ']'))
            if (v[1] == ']' && v[2] == '>') {
              why = "\"]]>\" in character data";
              return false;
            }
        return true;
      },
      [&](pugi::xml_node) {
        m.close_scope();
        return true;
      });
  return why;
}

void DomEvents::walk(Sink& sink) {
  Impl& m = *impl_;
  m.bindings.resize(1);  // the xml prefix
  m.marks.clear();
  m.line_offset = 0;
  m.line_number = 1;
  m.traverse(
      [&](pugi::xml_node e) {
        m.open_scope(e, true);
        const char* local;
        bool prefixed;
        const char* qname = e.name();
        const Binding* b = m.resolve(qname, false, local, prefixed);
        const char* name = local;
        if (b && !b->uri.empty()) {
          m.name.assign(b->expanded).append(local);
          name = m.name.c_str();
        }
        // Room for every attribute's "URI local" name first: growing attr_names later would move the strings
        // whose c_str() atts already holds.
        std::size_t k = 0;
        for (pugi::xml_attribute a = e.first_attribute(); a; a = a.next_attribute()) ++k;
        if (m.attr_names.size() < k) m.attr_names.resize(k);
        m.atts.clear();
        k = 0;
        for (pugi::xml_attribute a = e.first_attribute(); a; a = a.next_attribute()) {
          const char* an = a.name();
          if (Impl::is_declaration(an)) continue;
          const char* al;
          bool ap;
          const Binding* ab = m.resolve(an, true, al, ap);
          if (ap) {
            m.attr_names[k].assign(ab->expanded).append(al);  // bound: load() checked
            m.atts.push_back(m.attr_names[k++].c_str());
          } else {
            m.atts.push_back(an);
          }
          m.atts.push_back(a.value());
        }
        m.atts.push_back(nullptr);
        m.current = e;
        m.at_end = false;
        sink.start(name, m.atts.data());
        return !sink.stopped();
      },
      [&](pugi::xml_node t) {
        if ((t.type() == pugi::node_pcdata || t.type() == pugi::node_cdata) && sink.wants_text()) {
          const char* v = t.value();
          sink.text(v, std::strlen(v));
        }
        return !sink.stopped();
      },
      [&](pugi::xml_node e) {
        m.current = e;
        m.at_end = true;
        sink.end();
        m.close_scope();
        return !sink.stopped();
      });
}

std::size_t DomEvents::line() const {
  const Impl& m = *impl_;
  if (!m.current) return 1;
  const std::size_t off = m.at_end ? m.end_event_offset(m.current)
                                   : static_cast<std::size_t>(m.current.offset_debug()) - 1;
  return m.line_at(off);
}

}  // namespace groundplan::gis::xml
