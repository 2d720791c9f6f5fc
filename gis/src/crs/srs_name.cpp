// SPDX-License-Identifier: MIT
// srsName forms met in CityGML files (issue 6; examples in ../shared/data/*/SOURCE.txt).
#include <groundplan/gis/crs.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <string>

namespace groundplan::gis {
namespace {

std::string lower(std::string_view s) {
  std::string r(s);
  std::transform(r.begin(), r.end(), r.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return r;
}

int to_int(std::string_view s) {
  int v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size() && v > 0 ? v : 0;
}

/// The EPSG code of one component: "crs:EPSG::25832", "crs:EPSG:6.12:25832", "EPSG:25832",
/// "urn:ogc:def:crs:EPSG::25832", ".../def/crs/EPSG/0/25832", "...epsg.xml#4326". 0 if none.
int epsg_of(std::string_view c) {
  std::string l = lower(c);
  std::size_t at = l.find("epsg");
  if (at == std::string::npos) return 0;
  // the code is the last run of digits after "epsg"
  std::size_t end = l.size();
  while (end > at && !std::isdigit(static_cast<unsigned char>(l[end - 1]))) --end;
  std::size_t begin = end;
  while (begin > at && std::isdigit(static_cast<unsigned char>(l[begin - 1]))) --begin;
  if (begin == end) return 0;
  // the character before the digits must be a separator, not the "." of a version such as 6.12
  char before = l[begin - 1];
  if (before != ':' && before != '/' && before != '#' && before != '=') return 0;
  // ...and what follows the digits may only be junk such as a closing slash
  return to_int(std::string_view(l).substr(begin, end - begin));
}

struct AdvEntry {
  const char* name;
  int epsg;
};
// AdV (German surveying authorities) CRS names: urn:adv:crs:<horizontal>[*<vertical>]
constexpr AdvEntry kAdvHorizontal[] = {
    {"etrs89_utm31", 25831}, {"etrs89_utm32", 25832}, {"etrs89_utm33", 25833}, {"dhdn_3gk2", 31466},
    {"dhdn_3gk3", 31467},    {"dhdn_3gk4", 31468},    {"dhdn_3gk5", 31469},    {"de_dhdn_3gk2", 31466},
    {"de_dhdn_3gk3", 31467}, {"de_dhdn_3gk4", 31468}, {"de_dhdn_3gk5", 31469}, {"etrs89_lat-lon", 4258},
    {"etrs89_3gk3", 5677},   {"etrs89_3gk4", 5678},   {"de_rd83_3gk4", 3398},  {"de_rd83_3gk5", 3399},
};
constexpr AdvEntry kAdvVertical[] = {
    {"de_dhhn92_nh", 5783}, {"de_dhhn2016_nh", 7837}, {"de_dhhn12_noh", 5784}, {"de_dhhn85_noh", 5784},
};

}  // namespace

SrsName parse_srs_name(std::string_view srs) {
  SrsName r;
  r.text = std::string(srs);
  while (!srs.empty() && std::isspace(static_cast<unsigned char>(srs.front()))) srs.remove_prefix(1);
  while (!srs.empty() && std::isspace(static_cast<unsigned char>(srs.back()))) srs.remove_suffix(1);
  if (srs.empty() || srs.front() == '#') {
    r.local = true;
    return r;
  }
  const std::string l = lower(srs);

  if (l.starts_with("urn:adv:crs:")) {
    std::string rest = l.substr(12);
    std::string h = rest.substr(0, rest.find('*'));
    std::string v = rest.find('*') == std::string::npos ? "" : rest.substr(rest.find('*') + 1);
    for (const auto& e : kAdvHorizontal)
      if (h == e.name) r.epsg = e.epsg;
    for (const auto& e : kAdvVertical)
      if (v == e.name) r.vertical_epsg = e.epsg;
  } else if (l.starts_with("urn:ogc:def:crs,") || l.starts_with("urn:x-ogc:def:crs,")) {
    // compound URN: urn:ogc:def:crs,crs:EPSG::25832,crs:EPSG::5783
    std::string_view s(l);
    s.remove_prefix(s.find(',') + 1);
    std::string_view first = s.substr(0, s.find(','));
    r.epsg = epsg_of(first);
    if (s.find(',') != std::string_view::npos) r.vertical_epsg = epsg_of(s.substr(s.find(',') + 1));
  } else if (l.find("crs-compound") != std::string::npos) {
    // http://www.opengis.net/def/crs-compound?1=http://www.opengis.net/def/crs/EPSG/0/25832&2=...
    std::size_t one = l.find("1=");
    std::size_t two = l.find("&2=");
    if (one != std::string::npos) r.epsg = epsg_of(l.substr(one + 2, two == std::string::npos ? std::string::npos : two - one - 2));
    if (two != std::string::npos) r.vertical_epsg = epsg_of(l.substr(two + 3));
  } else if (l.starts_with("epsg:") && l.find('+') != std::string::npos) {
    // EPSG:25832+5783
    r.epsg = to_int(std::string_view(l).substr(5, l.find('+') - 5));
    r.vertical_epsg = to_int(std::string_view(l).substr(l.find('+') + 1));
  } else if (l.find("epsg") != std::string::npos &&
             (l.starts_with("epsg") || l.starts_with("urn:") || l.starts_with("http://") || l.starts_with("https://"))) {
    r.epsg = epsg_of(l);
  } else if (l.starts_with("urn:ogc:def:crs:ogc:") || l.starts_with("urn:ogc:def:crs:ogc::")) {
    if (l.ends_with("crs84") || l.ends_with("crs84h")) r.definition = "OGC:CRS84";
  } else if (l.starts_with("urn:ogc:def:crs:local") || l.starts_with("local")) {
    r.local = true;
    return r;
  }
  if (r.epsg) r.definition = "EPSG:" + std::to_string(r.epsg);
  else if (r.definition.empty()) r.definition = std::string(srs);
  return r;
}

}  // namespace groundplan::gis
