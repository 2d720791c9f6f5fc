#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""groundplan.union against shapely.ops.unary_union (Debian's GEOS) and GEOS DisjointSubsetUnion (issue 23).

All three on the same list of Shapely polygons, in one run. Reports medians of --repeat runs, wall and CPU
seconds (CPU: time.process_time(), all threads of the process), with groundplan's conversion in and out of
Python measured apart:
  to_wkb      Shapely -> engine input (Python side: the GEOS addresses, or WKB bytes)
  parse       engine input -> engine footprints (C++)
  union       the exact union (the engine)
  out         plans -> GEOS polygons or WKB, and the Python lists (C++)
  from_wkb    -> Shapely polygons (Python side)
DisjointSubsetUnion (GEOS >= 3.12, which Debian bookworm lacks) is called through ctypes from the libgeos_c
named by --dsu-lib or $GEOS_DSU_LIB (skipped when neither names one); what its time counts, to be fair (WKB in,
WKB out): Shapely -> WKB (one reused WKBWriter on Shapely 1.x, vectorised to_wkb on 2.x), the WKBs joined into
one GeometryCollection read by that GEOS in one call, DisjointSubsetUnion, the result written as one WKB,
read back by Shapely and split into its polygons (the form groundplan.union returns), and the GEOS frees.
Usage: PYTHONPATH=build/python python3 tests/bench/python_union_bench.py [--n 60000] [--repeat 3]
       [--threads 0] [--dsu-lib PATH/libgeos_c.so.1] [--input CITYGML_OR_FOLDER ...]
       (--input: real footprints read by groundplan.read; --threads also applies to the DSU comparison's
       groundplan run, which is on one core unless told otherwise by --dsu-threads)
"""
import argparse
import ctypes
import os
import pathlib
import statistics
import struct
import sys
import time

import groundplan
import shapely
import shapely.wkb
from shapely.ops import unary_union

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python"))
from synthetic_city import block_city  # noqa: E402  (the tests' generator)

SHAPELY2 = int(shapely.__version__.split(".")[0]) >= 2


def median_of(runs, key):
    return statistics.median(r[key] for r in runs)


class Dsu:
    """GEOSDisjointSubsetUnion_r of a libgeos_c of its own (loaded apart from Shapely's: RTLD_DEEPBIND)."""

    def __init__(self, path, symbol="GEOSDisjointSubsetUnion_r"):
        lib = ctypes.CDLL(path, mode=os.RTLD_LOCAL | getattr(os, "RTLD_DEEPBIND", 0))
        vp, sz = ctypes.c_void_p, ctypes.c_size_t
        for name, res, args in (
            ("GEOSversion", ctypes.c_char_p, []),
            ("GEOS_init_r", vp, []),
            ("GEOSWKBReader_create_r", vp, [vp]),
            ("GEOSWKBReader_read_r", vp, [vp, vp, ctypes.c_char_p, sz]),
            ("GEOSWKBWriter_create_r", vp, [vp]),
            ("GEOSWKBWriter_write_r", ctypes.POINTER(ctypes.c_char), [vp, vp, vp, ctypes.POINTER(sz)]),
            (symbol, vp, [vp, vp]),
            ("GEOSGeom_destroy_r", None, [vp, vp]),
            ("GEOSFree_r", None, [vp, vp]),
        ):
            f = getattr(lib, name)  # AttributeError: a GEOS without DisjointSubsetUnion (< 3.12)
            f.restype, f.argtypes = res, args
        self.lib, self.union = lib, getattr(lib, symbol)
        self.version = lib.GEOSversion().decode()
        self.h = lib.GEOS_init_r()
        self.reader = lib.GEOSWKBReader_create_r(self.h)
        self.writer = lib.GEOSWKBWriter_create_r(self.h)

    def union_wkb(self, wkbs):
        """WKB bytes in (one GeometryCollection), WKB bytes of the union out."""
        lib, h = self.lib, self.h
        collection = struct.pack("<BII", 1, 7, len(wkbs)) + b"".join(wkbs)
        g = lib.GEOSWKBReader_read_r(h, self.reader, collection, len(collection))
        if not g:
            raise RuntimeError("DSU's GEOS could not read the footprints")
        u = self.union(h, g)
        lib.GEOSGeom_destroy_r(h, g)
        if not u:
            raise RuntimeError("the union of DSU's GEOS failed")
        size = ctypes.c_size_t()
        buf = lib.GEOSWKBWriter_write_r(h, self.writer, u, ctypes.byref(size))
        out = ctypes.string_at(buf, size.value)
        lib.GEOSFree_r(h, ctypes.cast(buf, ctypes.c_void_p))
        lib.GEOSGeom_destroy_r(h, u)
        return out


def shapely_to_wkbs(geoms):
    if SHAPELY2:
        return list(shapely.to_wkb(geoms, output_dimension=2))
    from shapely.geos import WKBWriter, lgeos

    write = WKBWriter(lgeos).write
    return [write(g) for g in geoms]


def shapely_polygons(wkb):
    g = shapely.wkb.loads(wkb)
    return [g] if g.geom_type == "Polygon" else list(g.geoms)


def dsu_run(dsu, geoms):
    t0, c0 = time.perf_counter(), time.process_time()
    plans = shapely_polygons(dsu.union_wkb(shapely_to_wkbs(geoms)))
    return dict(total=time.perf_counter() - t0, total_cpu=time.process_time() - c0), plans


def ours_run(geoms, threads):
    r = groundplan.union(geoms, threads=threads)
    t = r.timings
    row = dict(to_wkb=t["to_wkb_s"], parse=t["parse_s"], union=t["union_s"], out=t["write_s"] + t["to_python_s"],
               from_wkb=t["from_wkb_s"], total=t["total_s"])
    nan = float("nan")  # a groundplan before CPU timings (to compare with an older build)
    t = dict({k + "_cpu_s": nan for k in ("to_wkb", "parse", "union", "write", "to_python", "from_wkb", "total")}, **t)
    row.update(to_wkb_cpu=t["to_wkb_cpu_s"], parse_cpu=t["parse_cpu_s"], union_cpu=t["union_cpu_s"],
               out_cpu=t["write_cpu_s"] + t["to_python_cpu_s"], from_wkb_cpu=t["from_wkb_cpu_s"], total_cpu=t["total_cpu_s"])
    return row, r


CONV = ("to_wkb", "parse", "out", "from_wkb")


def report_ours(label, runs):
    print(f"| groundplan.union {label}: step | median wall s | median CPU s |")
    print("|---|---|---|")
    for k in CONV[:2] + ("union",) + CONV[2:] + ("total",):
        print(f"| {k} | {median_of(runs, k):.4f} | {median_of(runs, k + '_cpu'):.4f} |")
    conv = sum(median_of(runs, k) for k in CONV)
    conv_cpu = sum(median_of(runs, k + "_cpu") for k in CONV)
    total, total_cpu = median_of(runs, "total"), median_of(runs, "total_cpu")
    print(f"# {label}: conversion in and out {conv:.4f} s wall = {100 * conv / total:.1f} % of the total; "
          f"{conv_cpu:.4f} s CPU = {100 * conv_cpu / total_cpu:.1f} % of the total CPU")
    shares = [f"{100 * sum(r[k + '_cpu'] for k in CONV) / r['total_cpu']:.1f}" for r in runs]
    print(f"# {label}: conversion's share of the CPU time, call by call (the first pays the page faults of fresh "
          f"memory): {', '.join(shares)} %")
    return total, total_cpu


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=60000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--dsu-lib", default=os.environ.get("GEOS_DSU_LIB"),
                    help="a libgeos_c.so.1 of GEOS >= 3.12 (default: $GEOS_DSU_LIB); absent: DSU skipped")
    ap.add_argument("--dsu-symbol", default="GEOSDisjointSubsetUnion_r",
                    help="GEOSUnaryUnion_r checks this comparison's plumbing with a GEOS < 3.12 (not a DSU figure)")
    ap.add_argument("--dsu-threads", type=int, default=1, help="groundplan's threads in the DSU comparison (1 core)")
    ap.add_argument("--no-unary-union", action="store_true", help="skip shapely.ops.unary_union (slow)")
    ap.add_argument("--wkb", action="store_true",
                    help="force the WKB route (what a Shapely with a libgeos_c of its own, e.g. a wheel, gets)")
    ap.add_argument("--input", nargs="*", help="CityGML/CityJSON ... whose footprints to unite instead")
    a = ap.parse_args()
    if a.wkb:
        groundplan._geos_addresses = lambda geometries: None
    if a.input:
        geoms = [g for g in groundplan.read(a.input).footprints.geometry if g.is_valid and not g.is_empty]
        what = f"{len(geoms)} valid real footprints from {' '.join(a.input)}"
    else:
        geoms = block_city(a.n)
        what = f"{len(geoms)} generated footprints"
    geos_version = shapely.geos_version_string if SHAPELY2 else shapely.geos.geos_version_string
    print(f"# {what}; shapely {shapely.__version__}, GEOS {geos_version}; groundplan from {groundplan.__file__}"
          f"{'; WKB route forced' if a.wkb else ''}")
    dsu = None
    if a.dsu_lib:
        try:
            dsu = Dsu(a.dsu_lib, a.dsu_symbol)
            print(f"# {a.dsu_symbol} from {a.dsu_lib} (GEOS {dsu.version})")
        except (OSError, AttributeError) as e:
            print(f"# DisjointSubsetUnion skipped: {a.dsu_lib}: {e}")
    else:
        print("# DisjointSubsetUnion skipped: no --dsu-lib / GEOS_DSU_LIB")

    ours, ours1, geos, dsus = [], [], [], []
    for _ in range(a.repeat):
        row, r = ours_run(geoms, a.threads)
        ours.append(row)
        if dsu is not None:
            row1, r1 = ours_run(geoms, a.dsu_threads)
            ours1.append(row1)
            d, dsu_plans = dsu_run(dsu, geoms)
            dsus.append(d)
        if not a.no_unary_union:
            t0, c0 = time.perf_counter(), time.process_time()
            ref = unary_union(geoms)
            geos.append(dict(total=time.perf_counter() - t0, total_cpu=time.process_time() - c0))
    if not a.no_unary_union:
        got = unary_union(r.plans) if len(r.plans) < 20000 else None
        if got is not None:
            print(f"# symmetric difference / area: {ref.symmetric_difference(got).area / ref.area:.2e}; plans {len(r.plans)}")
        else:
            print(f"# plans {len(r.plans)}; area {sum(r.areas):.1f} vs GEOS {ref.area:.1f}")
    if dsu is not None:
        area = sum(p.area for p in dsu_plans)
        print(f"# {a.dsu_symbol}: {len(dsu_plans)} polygons, area {area:.3f}; groundplan: {len(r1.plans)} plans, area {sum(r1.areas):.3f}")

    total, total_cpu = report_ours(f"threads={a.threads}", ours)
    if not a.no_unary_union:
        g, gc = median_of(geos, "total"), median_of(geos, "total_cpu")
        print(f"| shapely.ops.unary_union | {g:.4f} | {gc:.4f} |")
        print(f"# speed-up over unary_union (threads={a.threads}): {g / total:.2f}x wall, {gc / total_cpu:.2f}x CPU")
    if dsu is not None:
        t1, c1 = report_ours(f"threads={a.dsu_threads}", ours1)
        d, dc = median_of(dsus, "total"), median_of(dsus, "total_cpu")
        print(f"| GEOS {a.dsu_symbol} (WKB in and out, Shapely conversion included) | {d:.4f} | {dc:.4f} |")
        print(f"# {a.dsu_symbol} / groundplan.union(threads={a.dsu_threads}), conversion in and out of Python included: "
              f"{d / t1:.2f}x wall, {dc / c1:.2f}x CPU")


if __name__ == "__main__":
    main()
