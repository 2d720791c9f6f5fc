#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes a generated tiled city for the tiled run's memory benchmark (issue 15): a grid of TX x TY CityGML tiles,
each K x K shifted copies of a real tile's buildings (as gen_big_citygml.py: unique gml:ids, streaming, constant
memory). Copies sit GAP metres apart (default -3: neighbouring copies overlap by 3 m, so buildings on a copy's
edge meet the next copy's, across tile edges too: seams). Not run in CI; figures in RESULTS.md.
Usage: gen_tiled_city.py OUT_DIR TX TY K [GAP] [SOURCE.gml] [--rows=J0:J1]
--rows writes only the tile rows J0 <= j < J1 of the same grid (several processes write one city side by side)."""
import pathlib
import sys

from gen_big_citygml import DEFAULT, Template


def main():
    rows = [a for a in sys.argv[1:] if a.startswith("--rows=")]
    argv = [a for a in sys.argv if not a.startswith("--rows=")]
    out, tx, ty, k = pathlib.Path(argv[1]), int(argv[2]), int(argv[3]), int(argv[4])
    gap = float(argv[5]) if len(argv) > 5 else -3.0
    src = pathlib.Path(argv[6]) if len(argv) > 6 else DEFAULT
    j0, j1 = (int(v) for v in rows[-1][len("--rows="):].split(":")) if rows else (0, ty)
    t = Template(src)
    dx, dy = t.width + gap, t.height + gap
    out.mkdir(parents=True, exist_ok=True)
    total = 0
    for j in range(max(0, j0), min(ty, j1)):
        for i in range(tx):
            with (out / f"tile_{j:03d}_{i:03d}.gml").open("w", encoding="utf-8") as f:
                f.write(t.head)
                for cj in range(k):
                    for ci in range(k):
                        gx, gy = i * k + ci, j * k + cj
                        f.write(t.copy(dx * gx, dy * gy, f"g{gx}_{gy}_"))
                        total += t.members
                f.write(t.tail)
    print(f"{out}: {tx * (min(ty, j1) - max(0, j0))} tiles of {k}x{k} copies, {total} buildings")


if __name__ == "__main__":
    main()
