#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes a generated tiled city for the tiled run's memory benchmark (issue 15): a grid of TX x TY CityGML tiles,
each K x K shifted copies of a real tile's buildings (as gen_big_citygml.py: unique gml:ids, streaming, constant
memory). Copies sit GAP metres apart (default -3: neighbouring copies overlap by 3 m, so buildings on a copy's
edge meet the next copy's, across tile edges too: seams). Not run in CI; figures in RESULTS.md.
Usage: gen_tiled_city.py OUT_DIR TX TY K [GAP] [SOURCE.gml]"""
import pathlib
import re
import sys

HERE = pathlib.Path(__file__).resolve().parent
DEFAULT = HERE.parents[1] / "sample_data" / "niedersachsen-lorup" / "LoD1_24065862_2_2021-01-25.gml"
NUM3 = re.compile(r"(-?\d+(?:\.\d*)?)\s+(-?\d+(?:\.\d*)?)\s+(-?\d+(?:\.\d*)?)")
MEMBER = "<core:cityObjectMember>"


def main():
    out, tx, ty, k = pathlib.Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    gap = float(sys.argv[5]) if len(sys.argv) > 5 else -3.0
    src = pathlib.Path(sys.argv[6]) if len(sys.argv) > 6 else DEFAULT
    text = src.read_text(encoding="utf-8")
    first = text.index(MEMBER)
    last = text.rindex("</core:cityObjectMember>") + len("</core:cityObjectMember>")
    head, body, tail = text[:first], text[first:last], text[last:]
    xs, ys = [], []
    for m in NUM3.finditer(body):
        xs.append(float(m.group(1)))
        ys.append(float(m.group(2)))
    dx, dy = max(xs) - min(xs) + gap, max(ys) - min(ys) + gap
    pieces, triples, pos = [], [], 0
    for m in NUM3.finditer(body):
        pieces.append(body[pos:m.start()])
        triples.append((float(m.group(1)), float(m.group(2)), m.group(3)))
        pos = m.end()
    pieces.append(body[pos:])
    per_copy = body.count(MEMBER)
    out.mkdir(parents=True, exist_ok=True)
    total = 0
    for j in range(ty):
        for i in range(tx):
            with (out / f"tile_{j:03d}_{i:03d}.gml").open("w", encoding="utf-8") as f:
                f.write(head)
                for cj in range(k):
                    for ci in range(k):
                        gx, gy = i * k + ci, j * k + cj
                        ox, oy = dx * gx, dy * gy
                        parts = []
                        for p, (x, y, z) in zip(pieces, triples):
                            parts.append(p)
                            parts.append(f"{x + ox:.3f} {y + oy:.3f} {z}")
                        parts.append(pieces[-1])
                        f.write("".join(parts).replace('gml:id="', f'gml:id="g{gx}_{gy}_'))
                        total += per_copy
                f.write(tail)
    print(f"{out}: {tx * ty} tiles of {k}x{k} copies, {total} buildings")


if __name__ == "__main__":
    main()
