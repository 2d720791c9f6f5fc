// SPDX-License-Identifier: MIT
#include "self_crossing_generator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace groundplan::testing {
namespace {

using Rng = std::mt19937_64;

int pick(Rng& r, int a, int b) { return std::uniform_int_distribution<int>(a, b)(r); }

/// Shapes on an integer lattice, scaled by 1/den and moved to (x0, y0) at the end.
using Lattice = std::vector<std::pair<int, int>>;

Lattice shape(Rng& r) {
  const int a = pick(r, 3, 12), b = pick(r, 3, 12);  // size in lattice units
  switch (pick(r, 0, 8)) {
    case 0: return {{0, 0}, {a, b}, {a, 0}, {0, b}};                              // bow-tie
    case 1: return {{0, 0}, {a, 0}, {0, b}, {a, b}};                              // bow-tie, other diagonal
    case 2: return {{0, 0}, {a, 0}, {a, b}, {2 * a, b}, {2 * a, 2 * b}, {a, 2 * b}, {a, b}, {0, b}};  // figure-eight
                                                                                                      // through its own vertex
    case 3: return {{0, 0}, {2 * a, 0}, {a, b}, {2 * a, 2 * b}, {0, 2 * b}, {a, b}};  // two triangles touching at a
                                                                                   // vertex visited twice
    case 4: return {{0, 0}, {a, 0}, {a, b}, {a / 2, b}, {a / 2, b + pick(r, 1, 5)}, {a / 2, b}, {0, b}};  // spike out
    case 5: return {{0, 0}, {a, 0}, {a, b}, {a / 2, b}, {a / 2, b / 2}, {a / 2, b}, {0, b}};  // spike in (retraced)
    case 6: return {{0, 0}, {a, 0}, {a / 3, 0}, {a / 3, b}, {0, b}};             // part of an edge retraced
    case 7: return {{0, 0}, {2 * a, 2 * b}, {2 * a, 0}, {0, 2 * b}, {a, pick(r, 0, 2 * b)}};  // crossing twice
    default: return {{0, 0}, {2 * a, 3 * b}, {4 * a, 0}, {-a, 2 * b}, {5 * a, 2 * b}};  // pentagram
  }
}

/// A ring in metres and the same ring on the common lattice (kCommonDen units a metre, integers).
struct Placed {
  Ring metres, lattice;
};

Placed place(const Lattice& l, int den, int dx, int dy, int rot, double x0, double y0) {
  Placed out;
  const int scale = kCommonDen / den;
  for (auto [u, v] : l) {
    for (int k = 0; k < rot; ++k) std::tie(u, v) = std::make_pair(-v, u);  // exact quarter turns
    out.metres.push_back({x0 + static_cast<double>(u + dx) / den, y0 + static_cast<double>(v + dy) / den});
    out.lattice.push_back({x0 * kCommonDen + static_cast<double>((u + dx) * scale),
                           y0 * kCommonDen + static_cast<double>((v + dy) * scale)});
  }
  return out;
}

void reverse(Placed& p) {
  std::reverse(p.metres.begin(), p.metres.end());
  std::reverse(p.lattice.begin(), p.lattice.end());
}

}  // namespace

std::vector<Footprint> self_crossing_case(Rng& r, double x0, double y0, std::vector<Footprint>* on_lattice) {
  if (on_lattice && (x0 != std::floor(x0) || y0 != std::floor(y0)))
    throw std::invalid_argument("self_crossing_case: the lattice copy needs whole-metre x0, y0");
  std::vector<Footprint> out;
  auto add = [&](Placed shell, std::optional<Placed> hole) {
    Footprint f, g;
    if (hole) {
      f.polygons.push_back(Polygon{std::move(shell.metres), {std::move(hole->metres)}});
      g.polygons.push_back(Polygon{std::move(shell.lattice), {std::move(hole->lattice)}});
    } else {
      f.polygons.push_back(Polygon{std::move(shell.metres), {}});
      g.polygons.push_back(Polygon{std::move(shell.lattice), {}});
    }
    out.push_back(std::move(f));
    if (on_lattice) on_lattice->push_back(std::move(g));
  };
  const int den = pick(r, 0, 1) ? 7 : 11;  // lattice units are sevenths or elevenths of a metre
  const int n = pick(r, 1, 3);
  for (int i = 0; i < n; ++i) {
    Placed ring = place(shape(r), den, pick(r, -4, 4), pick(r, -4, 4), pick(r, 0, 3), x0, y0);
    if (pick(r, 0, 1)) reverse(ring);
    if (pick(r, 0, 5) == 0)  // a self-crossing hole in a quad around it
      add(place({{-30, -30}, {30, -30}, {30, 30}, {-30, 30}}, den, 0, 0, 0, x0, y0), std::move(ring));
    else
      add(std::move(ring), std::nullopt);
  }
  const int quads = pick(r, 0, 2);  // ordinary overlapping quads (general quadrilaterals)
  for (int i = 0; i < quads; ++i) {
    const int cx = pick(r, -6, 6), cy = pick(r, -6, 6);
    Lattice q{{cx - pick(r, 2, 9), cy - pick(r, 2, 9)}, {cx + pick(r, 2, 9), cy - pick(r, 2, 9)},
              {cx + pick(r, 2, 9), cy + pick(r, 2, 9)}, {cx - pick(r, 2, 9), cy + pick(r, 2, 9)}};
    add(place(q, den, 0, 0, 0, x0, y0), std::nullopt);
  }
  return out;
}

std::vector<Footprint> self_crossing_city(std::size_t n, std::uint64_t seed, double offset_x, double offset_y,
                                          std::vector<Footprint>* on_lattice) {
  Rng r(seed);
  std::vector<Footprint> city;
  std::vector<Footprint> lattice;
  std::size_t cell = 0;
  while (city.size() < n) {
    const std::size_t side = 32;
    const double x = offset_x + 4.0 * static_cast<double>(cell % side);
    const double y = offset_y + 4.0 * static_cast<double>(cell / side);
    ++cell;
    lattice.clear();
    std::vector<Footprint> here = self_crossing_case(r, x, y, on_lattice ? &lattice : nullptr);
    for (std::size_t i = 0; i < here.size() && city.size() < n; ++i) {
      here[i].source_id = "sc" + std::to_string(city.size());
      if (on_lattice) {
        lattice[i].source_id = here[i].source_id;
        on_lattice->push_back(std::move(lattice[i]));
      }
      city.push_back(std::move(here[i]));
    }
  }
  return city;
}

}  // namespace groundplan::testing
