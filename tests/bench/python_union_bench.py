#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""groundplan.union against shapely.ops.unary_union (GEOS) on the same footprints (issue 23).

Reports medians of --repeat runs, with groundplan's conversion in and out of Python measured apart:
  to_wkb      Shapely -> WKB bytes (Python side)
  parse       WKB -> engine footprints (C++, all threads)
  union       the exact union (the engine)
  out         plans -> WKB -> bytes objects (C++) and the members lists
  from_wkb    WKB -> Shapely polygons (Python side)
Usage: PYTHONPATH=build/python python3 tests/bench/python_union_bench.py [--n 60000] [--repeat 3]
       [--threads 0] [--input CITYGML_OR_FOLDER ...]   (--input: real footprints read by groundplan.read)
"""
import argparse
import math
import random
import statistics
import time

import groundplan
import shapely
from shapely.geometry import Polygon
from shapely.ops import unary_union


def city(n, seed=23, x0=500000.0, y0=5400000.0):
    """Rows of houses with shared walls and overlapping wings on a grid of blocks (like bench_union.cpp's
    synthetic city: buildings touch, overlap and stand apart), in UTM-like coordinates."""
    rng = random.Random(seed)
    out = []
    per_side = int(math.sqrt(n / 24.0)) + 1
    b = 0
    while len(out) < n:
        bx, by = x0 + (b % per_side) * 120.0, y0 + (b // per_side) * 120.0
        b += 1
        for row in range(3):
            x = bx
            y = by + row * 35.0
            for _ in range(8):
                w, d = rng.uniform(6, 12), rng.uniform(9, 14)
                out.append(Polygon([(x, y), (x + w, y), (x + w, y + d), (x, y + d)]))  # party walls: exact
                if rng.random() < 0.3:  # a rotated wing overlapping the back
                    cx, cy, a = x + w / 2, y + d + 1.5, rng.uniform(0, math.pi)
                    c, s = math.cos(a), math.sin(a)
                    out.append(Polygon([(cx + c * u - s * v, cy + s * u + c * v) for u, v in ((-2, -3), (2, -3), (2, 3), (-2, 3))]))
                x += w
    return out[:n]


def median_of(runs, key):
    return statistics.median(r[key] for r in runs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=60000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--input", nargs="*", help="CityGML/CityJSON ... whose footprints to unite instead")
    a = ap.parse_args()
    if a.input:
        geoms = [g for g in groundplan.read(a.input).footprints.geometry if g.is_valid and not g.is_empty]
        what = f"{len(geoms)} valid real footprints from {' '.join(a.input)}"
    else:
        geoms = city(a.n)
        what = f"{len(geoms)} generated footprints"
    print(f"# {what}; shapely {shapely.__version__}, GEOS {shapely.geos.geos_version_string if hasattr(shapely, 'geos') else shapely.geos_version_string}")

    ours, geos = [], []
    for _ in range(a.repeat):
        r = groundplan.union(geoms, threads=a.threads)
        t = r.timings
        ours.append(dict(to_wkb=t["to_wkb_s"], parse=t["parse_s"], union=t["union_s"],
                         out=t["write_s"] + t["to_python_s"], from_wkb=t["from_wkb_s"], total=t["total_s"]))
        t0 = time.perf_counter()
        ref = unary_union(geoms)
        geos.append(dict(total=time.perf_counter() - t0))
    got = unary_union(r.plans) if len(r.plans) < 20000 else None
    if got is not None:
        print(f"# symmetric difference / area: {ref.symmetric_difference(got).area / ref.area:.2e}; plans {len(r.plans)}")
    else:
        print(f"# plans {len(r.plans)}; area {sum(r.areas):.1f} vs GEOS {ref.area:.1f}")
    conv = sum(median_of(ours, k) for k in ("to_wkb", "parse", "out", "from_wkb"))
    total = median_of(ours, "total")
    print("| step | median s |")
    print("|---|---|")
    for k in ("to_wkb", "parse", "union", "out", "from_wkb", "total"):
        print(f"| groundplan {k} | {median_of(ours, k):.3f} |")
    print(f"| shapely.ops.unary_union | {median_of(geos, 'total'):.3f} |")
    print(f"# conversion in and out: {conv:.3f} s = {100 * conv / total:.1f} % of groundplan's total; "
          f"speed-up over unary_union {median_of(geos, 'total') / total:.2f}x")


if __name__ == "__main__":
    main()
