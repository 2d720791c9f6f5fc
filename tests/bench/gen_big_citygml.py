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


class Template:
    """A real tile's buildings cut once into the text between coordinate triples and the triples as numbers, so
    that shifted copies are written without parsing again (also used by gen_tiled_city.py)."""

    def __init__(self, src):
        text = src.read_text(encoding="utf-8")
        first = text.index("<core:cityObjectMember>")
        last = text.rindex("</core:cityObjectMember>") + len("</core:cityObjectMember>")
        self.head, body, self.tail = text[:first], text[first:last], text[last:]
        self.members = body.count("<core:cityObjectMember>")
        xs, ys = [], []
        self.pieces, self.triples, pos = [], [], 0
        for m in NUM3.finditer(body):
            xs.append(float(m.group(1)))
            ys.append(float(m.group(2)))
            self.pieces.append(body[pos:m.start()])
            self.triples.append((float(m.group(1)), float(m.group(2)), m.group(3)))
            pos = m.end()
        self.pieces.append(body[pos:])
        self.width, self.height = max(xs) - min(xs), max(ys) - min(ys)

    def copy(self, ox, oy, id_prefix):
        """The buildings shifted by (ox, oy), every gml:id prefixed."""
        parts = []
        for p, (x, y, z) in zip(self.pieces, self.triples):
            parts.append(p)
            parts.append(f"{x + ox:.3f} {y + oy:.3f} {z}")
        parts.append(self.pieces[-1])
        return "".join(parts).replace('gml:id="', f'gml:id="{id_prefix}')


def main():
    out, size_mb = pathlib.Path(sys.argv[1]), float(sys.argv[2])
    src = pathlib.Path(sys.argv[3]) if len(sys.argv) > 3 else DEFAULT
    t = Template(src)
    dx, dy = t.width + 100.0, t.height + 100.0
    target = int(size_mb * 1e6)
    written, copy = 0, 0
    with out.open("w", encoding="utf-8") as f:
        f.write(t.head)
        written += len(t.head)
        while written < target:
            chunk = t.copy(dx * (copy % 64), dy * (copy // 64), f"c{copy}_")
            f.write(chunk)
            written += len(chunk)
            copy += 1
        f.write(t.tail)
    print(f"{out}: {written / 1e6:.0f} MB, {copy} copies of {src.name}")


if __name__ == "__main__":
    main()
