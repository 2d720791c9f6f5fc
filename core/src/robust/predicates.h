// SPDX-License-Identifier: MIT
#pragma once
// Every orientation and intersection decision of the union engine (STYLE.md §5): nothing outside
// core/src/robust decides a sign. Inputs are doubles; results are exact.
//
// Each predicate climbs a ladder and stops at the first rung that can certify the sign:
//   rung 0  double arithmetic with a certified forward error bound (Shewchuk's ccwerrboundA for the
//           2x2 determinant, a propagated bound for the degree-4 crossing comparison);
//   rung 1  double-double arithmetic (differences exact, products with ~2^-104 relative error)
//           with its own certified bound;
//   rung 2  MPFR, exact: every operation is checked exact through MPFR's ternary value, and the
//           precision is raised until it is (no fixed high precision everywhere).
// The paper (§6.3) raises precision dynamically; this is that idea with certified filters.
// Counters (per rung) let tests check that escalation happens only when needed.
// The error bounds assume no fused multiply-add: this directory is compiled with -ffp-contract=off.
#include <groundplan/types.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace groundplan::robust {

/// Which predicate family a counter belongs to.
enum class Family : int { Cross = 0, CompareCrossings = 1, Visibility = 2 };

/// Decisions taken at each rung since the last reset, per family (relaxed atomics; thread-safe).
struct RungStats {
  std::array<std::array<std::uint64_t, 3>, 3> count{};  // [family][rung]
  std::uint64_t at(Family f, int rung) const { return count[static_cast<int>(f)][rung]; }
};
RungStats rung_stats();
void reset_rung_stats();

namespace detail {
int cross_sign_slow(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1);
extern thread_local std::uint64_t t_cross_rung0;  // folded into rung_stats()
}  // namespace detail

/// Sign (-1, 0, +1) of the cross product (p1 - p0) x (q1 - q0), exactly. Rung 0 is inline: the
/// double result with Shewchuk's bound (3 + 16u)u (|t1| + |t2|); exact zero differences make the
/// double result exact (axis-parallel walls).
inline int cross_sign(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1) {
  constexpr double kU = 0x1p-53;
  const double t1 = (p1.x - p0.x) * (q1.y - q0.y);
  const double t2 = (p1.y - p0.y) * (q1.x - q0.x);
  const double v = t1 - t2;
  const double err = (3.0 + 16.0 * kU) * kU * ((t1 < 0 ? -t1 : t1) + (t2 < 0 ? -t2 : t2));
  if (v > err || -v > err || err == 0) {
    ++detail::t_cross_rung0;
    return (v > 0) - (v < 0);
  }
  return detail::cross_sign_slow(p0, p1, q0, q1);
}

/// Orientation of c relative to the directed line a->b: +1 left (counter-clockwise), -1 right, 0 on it.
inline int orient(const Point2& a, const Point2& b, const Point2& c) { return cross_sign(a, b, a, c); }

/// The lines of f and g are not parallel to a->b. Returns the sign of t_f - t_g, where t is the
/// parameter along a->b of the point where the line of f (g) meets the line a->b: -1 when f's
/// point comes first. Exact for any such points, inside the segment a->b or not.
int compare_crossings(const Point2& a, const Point2& b, const Point2& f0, const Point2& f1, const Point2& g0,
                      const Point2& g1);

/// One candidate of the nearest-crossing search: a segment crossing a->b properly.
struct Segment {
  Point2 p0, p1;
};

/// Paper §6.3, the visibility bisection: of the segments (each crossing a->b properly), the indices
/// of those whose crossing is nearest to a (several when they cross at exactly the same point).
/// A point q(tau) = a + tau (b - a) is "visible" from segment t when q is still on a's side of t;
/// bisecting tau splits the candidates into invisible (crossing before q), visible (after) and
/// uncertain. Each classification is certified in double; only the candidates the interval can no
/// longer separate go to compare_crossings, which escalates on its own.
std::vector<std::size_t> nearest_crossings(const Point2& a, const Point2& b, const std::vector<Segment>& segs);

/// The crossing point of segment a->b with the line f0->f1 (precondition: proper crossing): the exact
/// point correctly rounded to the nearest double in each coordinate (long double with a certified
/// error bound; MPFR when the bound cannot decide). The result is a function of the exact point
/// alone: one crossing, met along any pair of the edges through it, in any order or direction, is
/// always the same double point (issue 20).
Point2 crossing_point(const Point2& a, const Point2& b, const Point2& f0, const Point2& f1);

}  // namespace groundplan::robust
