// SPDX-License-Identifier: MIT
#pragma once
// --lod / LOD= values (issue 16): "-1" (the highest each building has), "0".."4", or a LoD with its
// refinement as 3DBAG names them ("1.2", "1.3", "2.2"). CityGML has no refinements: "2.2" reads LoD 2.
#include <string_view>

namespace groundplan::gis {

struct LodChoice {
  int lod = -1;         // -1 = highest
  int refinement = -1;  // 0..9 after the point; -1 = the highest of that LoD
};

/// Throws InvalidArgument starting with `what` + text (what = "--lod " or "open option LOD=") for anything else.
LodChoice parse_lod_choice(std::string_view text, std::string_view what);

}  // namespace groundplan::gis
