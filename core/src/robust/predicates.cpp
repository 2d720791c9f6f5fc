// SPDX-License-Identifier: MIT
// Adaptive-precision predicates (paper §6.3; Shewchuk 1997 for the rung-0 bound of the 2x2
// determinant; Ozaki et al. 2016 / GEOS CGAlgorithmsDD for the double -> double-double ladder).
#include "robust/predicates.h"

#include <mpfr.h>

#include <algorithm>
#include <limits>
#include <utility>
#include <cmath>

namespace groundplan::robust {
namespace {

constexpr double kU = 0x1p-53;                    // unit roundoff of double
constexpr double kCcwErrBoundA = (3.0 + 16.0 * kU) * kU;  // Shewchuk, predicates.c
constexpr double kDDBound = 32.0 * kU * kU;      // generous bound for one double-double 2x2 determinant

// Counters of the calling thread (tests run predicates on their own thread).
thread_local RungStats t_stats;

inline void count(Family f, int rung) { ++t_stats.count[static_cast<int>(f)][rung]; }

inline int sgn(double v) { return (v > 0) - (v < 0); }

// ---- double-double ---------------------------------------------------------------------------
struct DD {
  double hi = 0, lo = 0;
};

inline DD two_sum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}
inline DD quick_two_sum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}
inline DD two_diff(double a, double b) {  // exact a - b
  const double x = a - b;
  const double bvirt = a - x;
  const double avirt = x + bvirt;
  return {x, (a - avirt) + (bvirt - b)};
}
inline void split(double a, double& hi, double& lo) {
  constexpr double kSplitter = 134217729.0;  // 2^27 + 1
  const double c = kSplitter * a;
  const double abig = c - a;
  hi = c - abig;
  lo = a - hi;
}
inline DD two_prod(double a, double b) {  // exact a * b (Dekker; no FMA assumed)
  const double p = a * b;
  double ah, al, bh, bl;
  split(a, ah, al);
  split(b, bh, bl);
  const double err = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
  return {p, err};
}
inline DD dd_mul(DD a, DD b) {
  DD p = two_prod(a.hi, b.hi);
  p.lo += a.hi * b.lo + a.lo * b.hi;
  return quick_two_sum(p.hi, p.lo);
}
inline DD dd_sub(DD a, DD b) {
  DD s = two_sum(a.hi, -b.hi);
  const DD t = two_sum(a.lo, -b.lo);
  s.lo += t.hi;
  s = quick_two_sum(s.hi, s.lo);
  s.lo += t.lo;
  return quick_two_sum(s.hi, s.lo);
}

// ---- MPFR, exact: every operation's ternary value must be 0, else retry with more bits ----------
constexpr mpfr_prec_t kMpPrecisions[] = {128, 512, 2200, 8800};  // 2200 bits cover any difference of doubles
constexpr int kMpLevels = 4;

/// The MPFR numbers of one precision level, made once per thread: degenerate inputs (many exact
/// ties, e.g. the shadow of a triangulated model) reach this rung millions of times, and making and
/// freeing the numbers for each call cost a third of the time. Same precisions as made per call.
struct MpLevel {
  bool ready = false;
  mpfr_t dx1, dy1, dx2, dy2, t1, t2;  // mp_cross(): prec, prec, prec, prec, 2 prec, 2 prec
  mpfr_t o[4];                        // cross products: 2 prec + 2
  mpfr_t p1, p2, num;                 // products of those: 2 (2 prec + 2), and their difference (+ 2)
  void make(mpfr_prec_t prec) {
    for (mpfr_ptr v : {dx1, dy1, dx2, dy2}) mpfr_init2(v, prec);
    for (mpfr_ptr v : {t1, t2}) mpfr_init2(v, 2 * prec);
    const mpfr_prec_t po = 2 * prec + 2;
    for (mpfr_ptr v : o) mpfr_init2(v, po);
    for (mpfr_ptr v : {p1, p2}) mpfr_init2(v, 2 * po);
    mpfr_init2(num, 2 * po + 2);
    ready = true;
  }
  ~MpLevel() {
    if (!ready) return;
    for (mpfr_ptr v : {dx1, dy1, dx2, dy2, t1, t2, o[0], o[1], o[2], o[3], p1, p2, num}) mpfr_clear(v);
  }
};

MpLevel& mp_level(int i) {
  thread_local MpLevel levels[kMpLevels];
  MpLevel& l = levels[i];
  if (!l.ready) l.make(kMpPrecisions[i]);
  return l;
}

/// (p1 - p0) x (q1 - q0) into out (of level L's precision 2 prec + 2); false if any step was inexact.
bool mp_cross(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1, MpLevel& L, mpfr_ptr out) {
  int inexact = 0;
  inexact |= mpfr_set_d(L.dx1, p1.x, MPFR_RNDN) | mpfr_sub_d(L.dx1, L.dx1, p0.x, MPFR_RNDN);
  inexact |= mpfr_set_d(L.dy1, p1.y, MPFR_RNDN) | mpfr_sub_d(L.dy1, L.dy1, p0.y, MPFR_RNDN);
  inexact |= mpfr_set_d(L.dx2, q1.x, MPFR_RNDN) | mpfr_sub_d(L.dx2, L.dx2, q0.x, MPFR_RNDN);
  inexact |= mpfr_set_d(L.dy2, q1.y, MPFR_RNDN) | mpfr_sub_d(L.dy2, L.dy2, q0.y, MPFR_RNDN);
  inexact |= mpfr_mul(L.t1, L.dx1, L.dy2, MPFR_RNDN);
  inexact |= mpfr_mul(L.t2, L.dy1, L.dx2, MPFR_RNDN);
  inexact |= mpfr_sub(out, L.t1, L.t2, MPFR_RNDN);
  return inexact == 0;
}

int mp_cross_sign(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1) {
  for (int i = 0; i < kMpLevels; ++i) {
    MpLevel& L = mp_level(i);
    if (mp_cross(p0, p1, q0, q1, L, L.o[0])) return mpfr_sgn(L.o[0]);
  }
  return 0;  // unreachable for finite input
}

// ---- rung 0/1 values with certified error bounds ---------------------------------------------
struct Approx {
  double v, err;
};

inline Approx cross_double(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1) {
  const double t1 = (p1.x - p0.x) * (q1.y - q0.y);
  const double t2 = (p1.y - p0.y) * (q1.x - q0.x);
  return {t1 - t2, kCcwErrBoundA * (std::fabs(t1) + std::fabs(t2))};
}

struct ApproxDD {
  DD v;
  double err;
};

inline ApproxDD cross_dd(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1) {
  const DD dx1 = two_diff(p1.x, p0.x), dy1 = two_diff(p1.y, p0.y);
  const DD dx2 = two_diff(q1.x, q0.x), dy2 = two_diff(q1.y, q0.y);
  const DD t1 = dd_mul(dx1, dy2), t2 = dd_mul(dy1, dx2);
  return {dd_sub(t1, t2), kDDBound * (std::fabs(t1.hi) + std::fabs(t2.hi))};
}

}  // namespace

namespace detail {
extern thread_local std::uint64_t t_cross_rung0;
}

RungStats rung_stats() {
  RungStats s = t_stats;
  s.count[static_cast<int>(Family::Cross)][0] += detail::t_cross_rung0;
  return s;
}
void reset_rung_stats() {
  t_stats = RungStats{};
  detail::t_cross_rung0 = 0;
}

namespace detail {
thread_local std::uint64_t t_cross_rung0 = 0;

int cross_sign_slow(const Point2& p0, const Point2& p1, const Point2& q0, const Point2& q1) {
  // Rung 1. When the four differences are exact doubles (the usual case: Sterbenz for nearby
  // coordinates) the determinant is the exact sum of two two_prod pairs, and summing those four
  // terms with two_sum is exact: the sign is certain, exact zeros included (collinear vertices on a
  // party wall), without MPFR. Otherwise double-double arithmetic with its certified bound.
  const DD dx1 = two_diff(p1.x, p0.x), dy1 = two_diff(p1.y, p0.y);
  const DD dx2 = two_diff(q1.x, q0.x), dy2 = two_diff(q1.y, q0.y);
  if (dx1.lo == 0 && dy1.lo == 0 && dx2.lo == 0 && dy2.lo == 0) {
    const DD t1 = two_prod(dx1.hi, dy2.hi), t2 = two_prod(dy1.hi, dx2.hi);
    double e[4] = {t1.lo, -t2.lo, t1.hi, -t2.hi};
    std::sort(e, e + 4, [](double x, double y) { return std::fabs(x) < std::fabs(y); });
    double q = e[0];
    double h[4];
    int nh = 0;
    for (int i = 1; i < 4; ++i) {
      const DD s2 = two_sum(q, e[i]);
      if (s2.lo != 0) h[nh++] = s2.lo;
      q = s2.hi;
    }
    h[nh++] = q;
    count(Family::Cross, 1);
    // non-overlapping components in increasing magnitude: the largest non-zero one gives the sign
    for (int i = nh - 1; i >= 0; --i)
      if (h[i] != 0) return sgn(h[i]);
    return 0;
  }
  const ApproxDD d = cross_dd(p0, p1, q0, q1);
  const double dv = d.v.hi + d.v.lo;
  if (dv > d.err || -dv > d.err) {
    count(Family::Cross, 1);
    return sgn(d.v.hi);
  }
  count(Family::Cross, 2);
  return mp_cross_sign(p0, p1, q0, q1);
}
}  // namespace detail

namespace {

/// Exact sign of Oga*Ofb - Ofa*Ogb with O_s(P) = (s1 - s0) x (P - s0).
int mp_crossing_num_sign(const Point2& a, const Point2& b, const Point2& f0, const Point2& f1, const Point2& g0,
                         const Point2& g1) {
  for (int i = 0; i < kMpLevels; ++i) {
    MpLevel& L = mp_level(i);
    mpfr_ptr ofa = L.o[0], ofb = L.o[1], oga = L.o[2], ogb = L.o[3];
    if (!mp_cross(f0, f1, f0, a, L, ofa) || !mp_cross(f0, f1, f0, b, L, ofb) || !mp_cross(g0, g1, g0, a, L, oga) ||
        !mp_cross(g0, g1, g0, b, L, ogb))
      continue;
    int inexact = mpfr_mul(L.p1, oga, ofb, MPFR_RNDN);
    inexact |= mpfr_mul(L.p2, ofa, ogb, MPFR_RNDN);
    inexact |= mpfr_sub(L.num, L.p1, L.p2, MPFR_RNDN);
    if (inexact == 0) return mpfr_sgn(L.num);
  }
  return 0;
}

}  // namespace

namespace {
/// Whether g0 and g1 lie on the line through f0 and f1 (f0 != f1), exactly.
bool on_one_line(const Point2& f0, const Point2& f1, const Point2& g0, const Point2& g1) {
  auto same = [](const Point2& u, const Point2& v) { return u.x == v.x && u.y == v.y; };
  if ((same(f0, g0) && same(f1, g1)) || (same(f0, g1) && same(f1, g0))) return true;
  return orient(f0, f1, g0) == 0 && orient(f0, f1, g1) == 0;
}
}  // namespace

int compare_crossings(const Point2& a, const Point2& b, const Point2& f0, const Point2& f1, const Point2& g0,
                      const Point2& g1) {
  // t_f - t_g = (Oga*Ofb - Ofa*Ogb) / ((Ofa - Ofb)(Oga - Ogb)), and Ofa - Ofb = (b - a) x (f1 - f0):
  // valid for crossings anywhere on the line (events are reused on collinear segments).
  const int sden = cross_sign(a, b, f0, f1) * cross_sign(a, b, g0, g1);
  if (sden == 0) return 0;  // precondition violated: a line parallel to a->b
  {
    const Approx fa = cross_double(f0, f1, f0, a), fb = cross_double(f0, f1, f0, b);
    const Approx ga = cross_double(g0, g1, g0, a), gb = cross_double(g0, g1, g0, b);
    const double p1 = ga.v * fb.v, p2 = fa.v * gb.v;
    const double num = p1 - p2;
    double err = std::fabs(ga.v) * fb.err + std::fabs(fb.v) * ga.err + ga.err * fb.err + std::fabs(fa.v) * gb.err +
                 std::fabs(gb.v) * fa.err + fa.err * gb.err;
    err += kU * (std::fabs(p1) + std::fabs(p2)) + kU * std::fabs(num);
    err *= 1.0 + 8.0 * kU;
    if (num > err || -num > err) {
      count(Family::CompareCrossings, 0);
      return sgn(num) * sden;
    }
  }
  // Exact ties, which no filter can certify, are mostly f and g on one line: the same edge of two
  // facets (a triangulated surface, one copy each way), or pieces of one wall. Then both cross a->b
  // at one point, t_f = t_g exactly (g0 != g1, as sden != 0); the exact test is two orientations.
  if (on_one_line(f0, f1, g0, g1)) {
    count(Family::CompareCrossings, 1);
    return 0;
  }
  {
    const ApproxDD fa = cross_dd(f0, f1, f0, a), fb = cross_dd(f0, f1, f0, b);
    const ApproxDD ga = cross_dd(g0, g1, g0, a), gb = cross_dd(g0, g1, g0, b);
    const DD p1 = dd_mul(ga.v, fb.v), p2 = dd_mul(fa.v, gb.v);
    const DD num = dd_sub(p1, p2);
    const double afa = std::fabs(fa.v.hi) * (1 + 4 * kU), afb = std::fabs(fb.v.hi) * (1 + 4 * kU);
    const double aga = std::fabs(ga.v.hi) * (1 + 4 * kU), agb = std::fabs(gb.v.hi) * (1 + 4 * kU);
    double err = aga * fb.err + afb * ga.err + ga.err * fb.err + afa * gb.err + agb * fa.err + fa.err * gb.err;
    err += kDDBound * (std::fabs(p1.hi) + std::fabs(p2.hi));
    err *= 1.0 + 8.0 * kU;
    const double nv = num.hi + num.lo;
    if (nv > err || -nv > err) {
      count(Family::CompareCrossings, 1);
      return sgn(num.hi) * sden;
    }
  }
  count(Family::CompareCrossings, 2);
  return mp_crossing_num_sign(a, b, f0, f1, g0, g1) * sden;
}

std::vector<std::size_t> nearest_crossings(const Point2& a, const Point2& b, const std::vector<Segment>& segs) {
  const std::size_t n = segs.size();
  if (n <= 1) return n == 1 ? std::vector<std::size_t>{0} : std::vector<std::size_t>{};
  struct Cand {
    Approx va, vb;
    int sa;  // exact sign of O(a): a is on this side, the crossing is where the sign flips
  };
  std::vector<Cand> c(n);
  for (std::size_t i = 0; i < n; ++i) {
    c[i].va = cross_double(segs[i].p0, segs[i].p1, segs[i].p0, a);
    c[i].vb = cross_double(segs[i].p0, segs[i].p1, segs[i].p0, b);
    c[i].sa = cross_sign(segs[i].p0, segs[i].p1, segs[i].p0, a);
  }
  std::vector<std::size_t> s(n);
  for (std::size_t i = 0; i < n; ++i) s[i] = i;
  std::vector<std::size_t> inv, vis, unc;
  double lo = 0, hi = 1;
  bool exact_scan = false;
  for (int iter = 0; iter < 60 && s.size() > 1; ++iter) {
    const double tau = 0.5 * (lo + hi);  // dyadic: 1 - tau is exact
    inv.clear();
    vis.clear();
    unc.clear();
    for (std::size_t i : s) {
      const Cand& k = c[i];
      const double w0 = (1.0 - tau) * k.va.v, w1 = tau * k.vb.v;
      const double val = w0 + w1;
      const double err = ((1.0 - tau) * k.va.err + tau * k.vb.err + 2 * kU * (std::fabs(w0) + std::fabs(w1)) +
                          kU * std::fabs(val)) *
                         (1.0 + 8.0 * kU);
      if (val > err || -val > err) {
        count(Family::Visibility, 0);
        (sgn(val) == k.sa ? vis : inv).push_back(i);  // still on a's side: q is visible, crossing after q
      } else {
        unc.push_back(i);
      }
    }
    if (!unc.empty()) {
      if (!inv.empty()) {
        inv.insert(inv.end(), unc.begin(), unc.end());
        s.swap(inv);
      }
      exact_scan = true;
      break;
    }
    if (!inv.empty()) {
      s.swap(inv);
      hi = tau;
    } else {
      s.swap(vis);
      lo = tau;
    }
  }
  if (s.size() > 1 || exact_scan) {
    // The interval cannot separate these: exact comparisons (each escalates only if it must).
    std::vector<std::size_t> best{s[0]};
    for (std::size_t k = 1; k < s.size(); ++k) {
      const std::size_t i = s[k], j = best[0];
      const int cmp = compare_crossings(a, b, segs[i].p0, segs[i].p1, segs[j].p0, segs[j].p1);
      if (cmp < 0) {
        best.assign(1, i);
      } else if (cmp == 0) {
        best.push_back(i);
      }
    }
    std::sort(best.begin(), best.end());
    return best;
  }
  return s;
}

namespace {

/// The exact crossing coordinate a.c + oa (b.c - a.c) / (oa - ob), correctly rounded to the nearest
/// double (ties to even), computed exactly in MPFR. Every operation is checked exact through its
/// ternary value; precision is raised until it is. Only the final division rounds, once.
struct MpCrossing {
  mpfr_prec_t prec = 0;
  mpfr_t fx, fy, ax, ay, bx, by, t1, t2, oa, ob, d, dc, num, r53;
  void make(mpfr_prec_t p) {
    if (prec != 0) clear();
    prec = p;
    for (mpfr_ptr v : {fx, fy, ax, ay, bx, by, t1, t2, oa, ob, d, dc, num}) mpfr_init2(v, p);
    mpfr_init2(r53, 53);
  }
  void clear() {
    for (mpfr_ptr v : {fx, fy, ax, ay, bx, by, t1, t2, oa, ob, d, dc, num, r53}) mpfr_clear(v);
    prec = 0;
  }
  ~MpCrossing() {
    if (prec != 0) clear();
  }
  /// Returns false when some step was inexact at this precision.
  bool run(const Point2& a, const Point2& b, const Point2& f0, const Point2& f1, Point2& out) {
    int inexact = 0;
    inexact |= mpfr_set_d(fx, f1.x, MPFR_RNDN) | mpfr_sub_d(fx, fx, f0.x, MPFR_RNDN);
    inexact |= mpfr_set_d(fy, f1.y, MPFR_RNDN) | mpfr_sub_d(fy, fy, f0.y, MPFR_RNDN);
    inexact |= mpfr_set_d(ax, a.x, MPFR_RNDN) | mpfr_sub_d(ax, ax, f0.x, MPFR_RNDN);
    inexact |= mpfr_set_d(ay, a.y, MPFR_RNDN) | mpfr_sub_d(ay, ay, f0.y, MPFR_RNDN);
    inexact |= mpfr_set_d(bx, b.x, MPFR_RNDN) | mpfr_sub_d(bx, bx, f0.x, MPFR_RNDN);
    inexact |= mpfr_set_d(by, b.y, MPFR_RNDN) | mpfr_sub_d(by, by, f0.y, MPFR_RNDN);
    inexact |= mpfr_mul(t1, fx, ay, MPFR_RNDN) | mpfr_mul(t2, fy, ax, MPFR_RNDN) | mpfr_sub(oa, t1, t2, MPFR_RNDN);
    inexact |= mpfr_mul(t1, fx, by, MPFR_RNDN) | mpfr_mul(t2, fy, bx, MPFR_RNDN) | mpfr_sub(ob, t1, t2, MPFR_RNDN);
    inexact |= mpfr_sub(d, oa, ob, MPFR_RNDN);
    if (inexact != 0) return false;
    if (mpfr_zero_p(d)) return false;  // not a proper crossing: the caller keeps its double estimate
    double* const c_out[2] = {&out.x, &out.y};
    const double c_a[2] = {a.x, a.y}, c_b[2] = {b.x, b.y};
    for (int k = 0; k < 2; ++k) {
      // c = (a.c * d + oa * (b.c - a.c)) / d
      inexact |= mpfr_set_d(dc, c_b[k], MPFR_RNDN) | mpfr_sub_d(dc, dc, c_a[k], MPFR_RNDN);
      inexact |= mpfr_mul(t1, oa, dc, MPFR_RNDN) | mpfr_mul_d(t2, d, c_a[k], MPFR_RNDN);
      inexact |= mpfr_add(num, t1, t2, MPFR_RNDN);
      if (inexact != 0) return false;
      mpfr_div(r53, num, d, MPFR_RNDN);
      *c_out[k] = mpfr_get_d(r53, MPFR_RNDN);
    }
    return true;
  }
};

thread_local MpCrossing t_mp_crossing;

/// Long-double estimate of one coordinate with a certified error bound: returns true and the
/// correctly rounded double when the whole interval [estimate - bound, estimate + bound], which
/// contains the exact value, rounds to one double.
template <class L>
bool certain_round(L est, L bound, double& out) {
  const L lo = std::nextafter(est - bound, -std::numeric_limits<L>::infinity());
  const L hi = std::nextafter(est + bound, std::numeric_limits<L>::infinity());
  const double dlo = static_cast<double>(lo), dhi = static_cast<double>(hi);
  if (dlo != dhi) return false;
  out = dlo;
  return true;
}

}  // namespace

Point2 crossing_point(const Point2& a_in, const Point2& b_in, const Point2& f0_in, const Point2& f1_in) {
  // One crossing, one rounding (issue 20). The point is the EXACT crossing rounded to the nearest
  // double in each coordinate (correct rounding), so it is a function of the exact point alone: the
  // same crossing met along any of its edges, in either direction, and a crossing where three or
  // more edges meet (every pair of them has the same exact point), all give the same double point.
  // (Before: the long-double arithmetic of each pair was rounded on its own; the canonical operand
  // order below fixed the first, not the second: union-open a676fee0, three edges through one
  // crossing, plans overlapping next to two output vertices one ulp apart.) Fast path: long double
  // with a certified error bound, used when the bound's interval rounds to one double; else MPFR.
  auto less = [](const Point2& p, const Point2& q) { return p.x < q.x || (p.x == q.x && p.y < q.y); };
  Point2 a = a_in, b = b_in, f0 = f0_in, f1 = f1_in;
  if (less(b, a)) std::swap(a, b);
  if (less(f1, f0)) std::swap(f0, f1);
  if (less(f0, a) || (f0 == a && less(f1, b))) {
    std::swap(a, f0);
    std::swap(b, f1);
  }
  using L = long double;
  constexpr L u = std::numeric_limits<L>::epsilon() / 2;  // unit roundoff of long double
  const L fx = L(f1.x) - L(f0.x), fy = L(f1.y) - L(f0.y);
  const L ax = L(a.x) - L(f0.x), ay = L(a.y) - L(f0.y);
  const L bx = L(b.x) - L(f0.x), by = L(b.y) - L(f0.y);
  const L oa = fx * ay - fy * ax;
  const L ob = fx * by - fy * bx;
  const L ma = std::fabs(fx * ay) + std::fabs(fy * ax), mb = std::fabs(fx * by) + std::fabs(fy * bx);
  // |oa - exact| <= 4u ma (+ higher order); doubled for those and for rounding of the bounds.
  const L ea = 8 * u * ma, eb = 8 * u * mb;
  const L d = oa - ob;
  const L ed = ea + eb + 2 * u * (ma + mb);
  const L t = oa / d;
  Point2 p{static_cast<double>(L(a.x) + t * (L(b.x) - L(a.x))), static_cast<double>(L(a.y) + t * (L(b.y) - L(a.y)))};
  bool certain = false;
  if (std::isfinite(t) && std::fabs(d) > 2 * ed) {
    // |t - exact t| <= (|oa| ed + |d| ea) / (|d| (|d| - ed)) + u |t|
    const L et = 2 * ((std::fabs(oa) * ed + std::fabs(d) * ea) / (std::fabs(d) * (std::fabs(d) - ed)) + u * std::fabs(t));
    const L dx = L(b.x) - L(a.x), dy = L(b.y) - L(a.y);
    const L x = L(a.x) + t * dx, y = L(a.y) + t * dy;
    const L ex = 2 * (et * std::fabs(dx) + 3 * u * std::fabs(t * dx) + 2 * u * std::fabs(x));
    const L ey = 2 * (et * std::fabs(dy) + 3 * u * std::fabs(t * dy) + 2 * u * std::fabs(y));
    Point2 q;
    certain = certain_round(x, ex, q.x) && certain_round(y, ey, q.y);
    if (certain) p = q;
  }
  if (!certain) {
    MpCrossing& M = t_mp_crossing;
    Point2 q = p;
    for (mpfr_prec_t prec : {mpfr_prec_t{512}, mpfr_prec_t{2400}, mpfr_prec_t{9000}, mpfr_prec_t{36000}}) {
      if (M.prec < prec) M.make(prec);
      if (M.run(a, b, f0, f1, q)) {
        p = q;
        break;
      }
    }
  }
  // The exact point lies in both segments' bounding boxes, and so does its correct rounding; the
  // clamp only matters for a caller that breaks the precondition (no proper crossing).
  const double xlo = std::max(std::min(a.x, b.x), std::min(f0.x, f1.x));
  const double xhi = std::min(std::max(a.x, b.x), std::max(f0.x, f1.x));
  const double ylo = std::max(std::min(a.y, b.y), std::min(f0.y, f1.y));
  const double yhi = std::min(std::max(a.y, b.y), std::max(f0.y, f1.y));
  p.x = std::clamp(p.x, xlo, std::max(xlo, xhi));
  p.y = std::clamp(p.y, ylo, std::max(ylo, yhi));
  return p;
}

}  // namespace groundplan::robust
