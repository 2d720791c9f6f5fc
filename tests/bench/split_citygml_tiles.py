#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Cuts a CityGML file into N tiles of about equal size at its cityObjectMember boundaries (issue 14's
benchmark: the same city as one file and as a folder of tiles, same buildings in the same order). Each
tile is the file's head (XML declaration, root start tag, envelope), its members, and the root's end
tag. Streams in 4 MiB reads: constant memory.
Usage: split_citygml_tiles.py IN.gml N OUT_DIR"""
import os
import pathlib
import sys

OPEN = b"<core:cityObjectMember"
CLOSE = b"</core:cityObjectMember>"


def main():
    src, n, out = pathlib.Path(sys.argv[1]), int(sys.argv[2]), pathlib.Path(sys.argv[3])
    out.mkdir(parents=True, exist_ok=True)
    size = os.path.getsize(src)
    with open(src, "rb") as f:
        start = f.read(1 << 24)
        first = start.index(OPEN)
        head = start[:first]
        root = head[head.index(b"<", head.index(b"?>") + 2) + 1:]
        root = root[:min(root.index(c) for c in (b" ", b">", b"\n") if c in root)]
        tail = b"\n</" + root + b">\n"
        per = (size - first) / n
        f.seek(first)
        k, written, buf = 0, 0, b""
        tile = open(out / "tile_00.gml", "wb")
        tile.write(head)
        while True:
            chunk = f.read(1 << 22)
            buf += chunk
            end = buf.rfind(CLOSE)
            if end >= 0:
                cut = end + len(CLOSE)
                pos = 0
                while pos < cut:  # member by member, so that a tile ends where its share is reached
                    e = buf.find(CLOSE, pos) + len(CLOSE)
                    tile.write(buf[pos:e])
                    written += e - pos
                    pos = e
                    if written >= per * (k + 1) and k + 1 < n:
                        tile.write(tail)
                        tile.close()
                        k += 1
                        tile = open(out / f"tile_{k:02d}.gml", "wb")
                        tile.write(head)
                buf = buf[cut:]
            if not chunk:
                break
        tile.write(tail)
        tile.close()
    print(f"{k + 1} tiles in {out}")


if __name__ == "__main__":
    main()
