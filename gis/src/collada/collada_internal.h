// SPDX-License-Identifier: MIT
#pragma once
// COLLADA entry point for the KML reader: the KMZ's byte budget is shared by all its entries.
#include <groundplan/gis/collada.h>

#include "xml/safe_xml.h"

#include <array>

namespace groundplan::gis::detail {

/// read_collada with the caller's budget (options.max_bytes is ignored) and `display` for messages.
Mesh read_collada_bounded(const std::string& path, const std::string& display, const std::string& source_id,
                          const ColladaOptions& options, xml::ByteBudget& budget, std::vector<Problem>& problems,
                          ColladaInfo& info);

/// 4x4 row-major matrix acting on column vectors (COLLADA's convention).
using Mat4 = std::array<double, 16>;
constexpr Mat4 kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
Mat4 multiply(const Mat4& a, const Mat4& b);
Point3 apply(const Mat4& m, const Point3& p);
/// Right-handed rotation by `angle_deg` about the axis (x, y, z); identity for a zero axis.
Mat4 rotation(double x, double y, double z, double angle_deg);
Mat4 translation(double x, double y, double z);
Mat4 scaling(double x, double y, double z);

}  // namespace groundplan::gis::detail
