# SPDX-License-Identifier: MIT
"""Generated footprints as Shapely polygons, for the Python module's tests and its benchmark
(tests/bench/python_union_bench.py imports this file): the shapes of tests/bench/bench_union.cpp's city."""
import math
import random


def city(n, seed=23, x0=500000.0, y0=5700000.0):
    """n rotated rectangles on a grid of blocks in UTM-like coordinates: neighbours overlap, touch or
    stand apart (the shapes of tests/bench/bench_union.cpp's generated city, smaller)."""
    from shapely.geometry import Polygon

    rng = random.Random(seed)
    side = max(1, int(math.sqrt(n)))
    out = []
    for i in range(n):
        cx = x0 + (i % side) * 12.0 + rng.uniform(-2, 2)
        cy = y0 + (i // side) * 12.0 + rng.uniform(-2, 2)
        w, h = rng.uniform(4, 14), rng.uniform(4, 14)
        a = rng.uniform(0, math.pi) if rng.random() < 0.3 else 0.0
        c, s = math.cos(a), math.sin(a)
        pts = [(cx + c * dx - s * dy, cy + s * dx + c * dy) for dx, dy in ((-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2))]
        out.append(Polygon(pts))
    return out


def block_city(n, seed=23, x0=500000.0, y0=5400000.0):
    """Blocks of row houses (exact party walls) with rotated wings overlapping their backs, 120 m apart: many
    independent blocks, like tests/bench/bench_union.cpp's synthetic city (and python_union_bench.py's)."""
    from shapely.geometry import Polygon

    rng = random.Random(seed)
    out = []
    per_side = int(math.sqrt(n / 24.0)) + 1
    b = 0
    while len(out) < n:
        bx, by = x0 + (b % per_side) * 120.0, y0 + (b // per_side) * 120.0
        b += 1
        for row in range(3):
            x, y = bx, by + row * 35.0
            for _ in range(8):
                w, d = rng.uniform(6, 12), rng.uniform(9, 14)
                out.append(Polygon([(x, y), (x + w, y), (x + w, y + d), (x, y + d)]))
                if rng.random() < 0.3:
                    cx, cy, a = x + w / 2, y + d + 1.5, rng.uniform(0, math.pi)
                    c, s = math.cos(a), math.sin(a)
                    out.append(Polygon([(cx + c * u - s * v, cy + s * u + c * v) for u, v in ((-2, -3), (2, -3), (2, 3), (-2, 3))]))
                x += w
    return out[:n]
