// SPDX-License-Identifier: MIT
#include <groundplan/error.h>
#include <groundplan/gis/lod_choice.h>

#include <string>

namespace groundplan::gis {

LodChoice parse_lod_choice(std::string_view text, std::string_view what) {
  std::string_view t = text;
  while (!t.empty() && (t.front() == ' ' || t.front() == '\t')) t.remove_prefix(1);
  while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.remove_suffix(1);
  LodChoice c;
  if (t == "-1") return c;
  auto digit = [](char ch, char hi) { return ch >= '0' && ch <= hi; };
  if (t.size() == 1 && digit(t[0], '4')) {
    c.lod = t[0] - '0';
    return c;
  }
  if (t.size() == 3 && digit(t[0], '4') && t[1] == '.' && digit(t[2], '9')) {
    c.lod = t[0] - '0';
    c.refinement = t[2] - '0';
    return c;
  }
  throw InvalidArgument(std::string(what) + std::string(text.substr(0, 40)) +
                        ": must be -1 (the highest), 0..4, or a LoD with its refinement as 3DBAG names them "
                        "(1.2, 1.3, 2.2)");
}

}  // namespace groundplan::gis
