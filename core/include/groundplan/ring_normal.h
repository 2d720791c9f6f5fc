// SPDX-License-Identifier: MIT
#pragma once
// Newell's normal of one ring of a Mesh: the readers and the footprint check ask it whether a face lies flat.
#include <groundplan/mesh.h>

#include <cstdint>

namespace groundplan {

/// Newell's normal of ring r of `m`, summed about the ring's first corner; its length is twice the ring's area on
/// its plane (0 for a ring of no area). Not normalised.
inline Point3 ring_normal(const Mesh& m, std::uint32_t r) {
  const std::uint32_t a = m.ring_offsets[r], b = m.ring_offsets[r + 1];
  Point3 n;
  if (b == a) return n;
  const Point3 o = m.vertices[m.indices[a]];
  for (std::uint32_t k = a; k < b; ++k) {
    const Point3& p = m.vertices[m.indices[k]];
    const Point3& q = m.vertices[m.indices[k + 1 < b ? k + 1 : a]];
    const double px = p.x - o.x, py = p.y - o.y, pz = p.z - o.z, qx = q.x - o.x, qy = q.y - o.y, qz = q.z - o.z;
    n.x += (py - qy) * (pz + qz);
    n.y += (pz - qz) * (px + qx);
    n.z += (px - qx) * (py + qy);
  }
  return n;
}

}  // namespace groundplan
