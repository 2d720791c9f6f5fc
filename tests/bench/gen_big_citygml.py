#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes a large CityGML (issue 8) by repeating the buildings of a real tile on a grid of shifted
copies, streaming (constant memory), with unique gml:ids. Not run in CI; figures in RESULTS.md.
Usage: gen_big_citygml.py OUT.gml SIZE_MB [SOURCE.gml]   (default source: the Niedersachsen LoD1 tile,
EPSG:25832, metres). Each copy is shifted by a multiple of the source's extent (+ a 100 m gap)."""
import pathlib
import re
import sys

HERE = pathlib.Path(__file__).resolve().parent
DEFAULT = HERE.parents[1] / "sample_data" / "niedersachsen-lorup" / "LoD1_24065862_2_2021-01-25.gml"
NUM3 = re.compile(r"(-?\d+(?:\.\d*)?)\s+(-?\d+(?:\.\d*)?)\s+(-?\d+(?:\.\d*)?)")


def main():
    out, size_mb = pathlib.Path(sys.argv[1]), float(sys.argv[2])
    src = pathlib.Path(sys.argv[3]) if len(sys.argv) > 3 else DEFAULT
    text = src.read_text(encoding="utf-8")
    first = text.index("<core:cityObjectMember>")
    last = text.rindex("</core:cityObjectMember>") + len("</core:cityObjectMember>")
    head, body, tail = text[:first], text[first:last], text[last:]
    xs, ys = [], []
    for m in NUM3.finditer(body):
        xs.append(float(m.group(1)))
        ys.append(float(m.group(2)))
    dx, dy = max(xs) - min(xs) + 100.0, max(ys) - min(ys) + 100.0
    # Pieces: text between coordinate triples, and the triples as numbers (one parse, many copies).
    pieces, triples, pos = [], [], 0
    for m in NUM3.finditer(body):
        pieces.append(body[pos:m.start()])
        triples.append((float(m.group(1)), float(m.group(2)), m.group(3)))
        pos = m.end()
    pieces.append(body[pos:])
    target = int(size_mb * 1e6)
    written, copy = 0, 0
    with out.open("w", encoding="utf-8") as f:
        f.write(head)
        written += len(head)
        while written < target:
            ox, oy = dx * (copy % 64), dy * (copy // 64)
            parts = []
            for p, (x, y, z) in zip(pieces, triples):
                parts.append(p)
                parts.append(f"{x + ox:.3f} {y + oy:.3f} {z}")
            parts.append(pieces[-1])
            chunk = "".join(parts).replace('gml:id="', f'gml:id="c{copy}_')
            f.write(chunk)
            written += len(chunk)
            copy += 1
        f.write(tail)
    print(f"{out}: {written / 1e6:.0f} MB, {copy} copies of {src.name}")


if __name__ == "__main__":
    main()
