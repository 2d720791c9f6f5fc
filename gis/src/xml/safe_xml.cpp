// SPDX-License-Identifier: MIT
#include "xml/safe_xml.h"
#include "files_read.h"

#include <groundplan/error.h>

#include <cpl_vsi.h>
#include <expat.h>

#include <cstring>
#include <memory>
#include <vector>

namespace groundplan::gis::xml {
namespace {

constexpr char kSep = ' ';  // namespace URI / local name separator: URIs cannot hold a space
constexpr std::size_t kChunk = 1 << 20;

void split(const char* name, std::string_view& uri, std::string_view& local) {
  const char* sp = std::strrchr(name, kSep);
  if (sp) {
    uri = std::string_view(name, static_cast<std::size_t>(sp - name));
    local = std::string_view(sp + 1);
  } else {
    uri = {};
    local = std::string_view(name);
  }
}

std::string mib(std::uint64_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

}  // namespace

SafeParser::SafeParser(std::string name, Handler& handler, std::size_t max_depth)
    : name_(std::move(name)), handler_(handler), max_depth_(max_depth) {
  parser_ = XML_ParserCreateNS(nullptr, kSep);
  if (!parser_) throw Error("out of memory creating the XML parser for " + name_);
  XML_SetUserData(parser_, this);
  XML_SetElementHandler(parser_, &SafeParser::on_start, &SafeParser::on_end);
  XML_SetCharacterDataHandler(parser_, &SafeParser::on_text);
  // As in the CityGML reader: no DTD, no parameter entities; no external entity handler is set, so
  // expat never opens anything; an entity declaration stops the parse.
  XML_SetParamEntityParsing(parser_, XML_PARAM_ENTITY_PARSING_NEVER);
  XML_SetEntityDeclHandler(parser_, &SafeParser::on_entity_decl);
  XML_SetUnparsedEntityDeclHandler(parser_, &SafeParser::on_unparsed_entity_decl);
}

SafeParser::~SafeParser() { XML_ParserFree(parser_); }

void SafeParser::feed(const char* data, std::size_t n, bool last) {
  if (n > static_cast<std::size_t>(INT32_MAX)) throw InputError(name_ + ": XML chunk too large");
  const XML_Status st = XML_Parse(parser_, data, static_cast<int>(n), last ? XML_TRUE : XML_FALSE);
  if (pending_) std::rethrow_exception(pending_);
  if (!stop_reason_.empty()) throw InputError(name_ + ": " + stop_reason_);
  if (st != XML_STATUS_OK) {
    const XML_Error code = XML_GetErrorCode(parser_);
    std::string msg = name_ + ": not well-formed XML at line " + std::to_string(XML_GetCurrentLineNumber(parser_)) +
                      ", column " + std::to_string(XML_GetCurrentColumnNumber(parser_)) + ": " + XML_ErrorString(code);
    if (code == XML_ERROR_NO_ELEMENTS || code == XML_ERROR_UNCLOSED_TOKEN || code == XML_ERROR_PARTIAL_CHAR)
      msg += " (the file looks truncated or is not XML)";
    throw InputError(msg);
  }
}

void SafeParser::stop(std::string reason) {
  if (stop_reason_.empty()) stop_reason_ = std::move(reason);
  XML_StopParser(parser_, XML_FALSE);
}

std::size_t SafeParser::line() const { return XML_GetCurrentLineNumber(parser_); }

void SafeParser::on_start(void* ud, const char* name, const char** atts) {
  auto* self = static_cast<SafeParser*>(ud);
  if (!self->stop_reason_.empty() || self->pending_) return;
  if (++self->depth_ > self->max_depth_) {
    self->stop("XML nesting deeper than " + std::to_string(self->max_depth_) +
               " levels; refused as hostile or broken");
    return;
  }
  try {
    std::string_view uri, local;
    split(name, uri, local);
    self->handler_.start(uri, local, atts);
  } catch (...) {
    self->pending_ = std::current_exception();
    XML_StopParser(self->parser_, XML_FALSE);
  }
}

void SafeParser::on_end(void* ud, const char* name) {
  auto* self = static_cast<SafeParser*>(ud);
  if (!self->stop_reason_.empty() || self->pending_) return;
  try {
    std::string_view uri, local;
    split(name, uri, local);
    self->handler_.end(uri, local);
  } catch (...) {
    self->pending_ = std::current_exception();
    XML_StopParser(self->parser_, XML_FALSE);
  }
  --self->depth_;
}

void SafeParser::on_text(void* ud, const char* s, int len) {
  auto* self = static_cast<SafeParser*>(ud);
  if (!self->capture_ || self->pending_) return;
  try {
    self->handler_.text(std::string_view(s, static_cast<std::size_t>(len)));
  } catch (...) {
    self->pending_ = std::current_exception();
    XML_StopParser(self->parser_, XML_FALSE);
  }
}

void SafeParser::on_entity_decl(void* ud, const char* name, int, const char*, int, const char*, const char*,
                                const char*, const char*) {
  static_cast<SafeParser*>(ud)->stop(std::string("the document declares the entity \"") + name +
                                     "\"; entity declarations are refused (entity-expansion and external-entity "
                                     "attacks; KML and COLLADA have no use for them)");
}

void SafeParser::on_unparsed_entity_decl(void* ud, const char* name, const char*, const char*, const char*,
                                         const char*) {
  on_entity_decl(ud, name, 0, nullptr, 0, nullptr, nullptr, nullptr, nullptr);
}

const char* attribute(const char** atts, std::string_view local) {
  for (; atts && *atts; atts += 2) {
    std::string_view n(atts[0]);
    const std::size_t sp = n.rfind(kSep);
    if (sp != std::string_view::npos) n = n.substr(sp + 1);
    if (n == local) return atts[1];
  }
  return nullptr;
}

namespace {

struct VsiFile {
  VSILFILE* f = nullptr;
  ~VsiFile() {
    if (f) VSIFCloseL(f);
  }
};

/// Opens `path` after checking its stated size against the budget.
VsiFile open_bounded(const std::string& path, const std::string& display, const ByteBudget& budget) {
  gis::note_file_opened(path);  // also when missing: a model added later changes the result
  VSIStatBufL st;
  if (VSIStatExL(path.c_str(), &st, VSI_STAT_EXISTS_FLAG | VSI_STAT_SIZE_FLAG) != 0)
    throw InputError(display + ": cannot open the file (does it exist and is it readable?)");
  const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (size > budget.max_entry_bytes)
    throw InputError(display + ": states " + std::to_string(size) + " bytes unpacked, over the limit of " +
                     mib(budget.max_entry_bytes) + " per file; refused (zip bomb?)");
  if (budget.used + size > budget.max_total_bytes)
    throw InputError(display + ": reading it would pass the limit of " + mib(budget.max_total_bytes) +
                     " unpacked bytes per input; refused (zip bomb?)");
  VsiFile file;
  file.f = VSIFOpenL(path.c_str(), "rb");
  if (!file.f) throw InputError(display + ": cannot open the file (does it exist and is it readable?)");
  return file;
}

/// Counts `n` more bytes of one entry; throws when a limit is passed.
void count(std::uint64_t& entry, std::uint64_t n, const std::string& display, ByteBudget& budget) {
  entry += n;
  budget.used += n;
  if (entry > budget.max_entry_bytes)
    throw InputError(display + ": unpacks to more than " + mib(budget.max_entry_bytes) +
                     " (the limit per file), more than its stated size; refused (zip bomb?)");
  if (budget.used > budget.max_total_bytes)
    throw InputError(display + ": the input unpacks to more than " + mib(budget.max_total_bytes) +
                     " (the limit per input); refused (zip bomb?)");
}

}  // namespace

void parse_vsi_file(const std::string& path, const std::string& display, SafeParser& parser, ByteBudget& budget) {
  VsiFile file = open_bounded(path, display, budget);
  std::vector<char> buf(kChunk);
  std::uint64_t entry = 0;
  for (;;) {
    const std::size_t n = VSIFReadL(buf.data(), 1, buf.size(), file.f);
    count(entry, n, display, budget);
    parser.feed(buf.data(), n, n == 0);
    if (n == 0) break;
  }
}

std::string read_vsi_file(const std::string& path, const std::string& display, ByteBudget& budget) {
  VsiFile file = open_bounded(path, display, budget);
  std::string out;
  std::uint64_t entry = 0;
  for (;;) {
    const std::size_t old = out.size();
    out.resize(old + kChunk);
    const std::size_t n = VSIFReadL(out.data() + old, 1, kChunk, file.f);
    out.resize(old + n);
    count(entry, n, display, budget);
    if (n == 0) break;
  }
  return out;
}

}  // namespace groundplan::gis::xml
