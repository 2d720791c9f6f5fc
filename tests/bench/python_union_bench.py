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
import pathlib
import statistics
import sys
import time

import groundplan
import shapely
from shapely.ops import unary_union

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python"))
from synthetic_city import block_city  # noqa: E402  (the tests' generator)


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
        geoms = block_city(a.n)
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
