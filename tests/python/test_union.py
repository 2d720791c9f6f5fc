# SPDX-License-Identifier: MIT
"""groundplan.union against Shapely's unary_union (GEOS), members, invalid input, arguments."""
import math
import os
import subprocess
import sys

import pytest
from shapely.geometry import MultiPolygon, Polygon
from shapely.ops import unary_union

from conftest import BUILD_DIR, PLATEAU, LORUP, block_city, city, groundplan, symdiff_rel


@pytest.fixture(params=["native", "wkb"])
def route(request, monkeypatch):
    """Each test once through the route the wrapper picks (Shapely 1.x on Debian: GEOS addresses) and once
    through WKB bytes (Shapely 2, or a Shapely with a libgeos_c of its own)."""
    if request.param == "wkb":
        monkeypatch.setattr(groundplan, "_geos_addresses", lambda geoms: None)
    return request.param


def check_against_geos(geoms, result):
    ref = unary_union(geoms)
    got = MultiPolygon(result.plans) if len(result.plans) != 1 else result.plans[0]
    assert all(p.is_valid for p in result.plans)
    assert symdiff_rel(ref, got) < 1e-9, f"symmetric difference {symdiff_rel(ref, got)}"
    parts = [ref] if ref.geom_type == "Polygon" else list(ref.geoms)
    assert len(result.plans) == len(parts)  # one plan per connected region, as GEOS's polygons


def check_members(geoms, result, skip=()):
    seen = {}
    for pi, members in enumerate(result.members):
        assert members == sorted(members)
        for m in members:
            assert m not in seen, f"input {m} is in plans {seen[m]} and {pi}"
            seen[m] = pi
    for i, g in enumerate(geoms):
        if i in skip:
            continue
        assert i in seen, f"input {i} is in no plan"
        plan = result.plans[seen[i]]
        assert g.difference(plan).area <= 1e-9 * g.area, f"plan {seen[i]} does not cover input {i}"


def test_generated_city_equals_unary_union(route):
    geoms = city(3000)
    r = groundplan.union(geoms)
    check_against_geos(geoms, r)
    check_members(geoms, r)
    assert r.problems == []
    import shapely

    if shapely.__version__ < "2":
        assert groundplan._shares_geos()  # Debian's Shapely 1.8 shares this module's libgeos_c
    if route == "wkb" or not groundplan._shares_geos():  # (a Shapely 2 wheel brings a libgeos_c of its own)
        assert r.timings["route"] == "wkb"
    else:
        assert r.timings["route"] == "geos"
    assert sum(r.areas) == pytest.approx(unary_union(geoms).area, rel=1e-9)


def test_block_city_equals_unary_union(route):
    geoms = block_city(5000, seed=4)  # party walls shared exactly, wings at angles
    r = groundplan.union(geoms)
    check_against_geos(geoms, r)
    check_members(geoms, r)


def test_one_thread_gives_the_same_plans():
    geoms = city(800, seed=5)
    a, b = groundplan.union(geoms, threads=1), groundplan.union(geoms, threads=2)
    assert sorted(a.members) == sorted(b.members)
    check_against_geos(geoms, a)
    check_members(geoms, a)
    check_members(geoms, b)


def test_real_footprints_reunited():
    """Footprints of real CityGML (PLATEAU, Lorup) read by groundplan.read, united again by union."""
    for path in (PLATEAU, LORUP):
        fps = groundplan.read(path).footprints
        geoms = [g for g in fps.geometry if g.is_valid and not g.is_empty]  # GEOS fails on invalid input
        assert len(geoms) > 50
        r = groundplan.union(geoms)
        check_against_geos(geoms, r)
        check_members(geoms, r)


def test_geoseries_and_wkb_input():
    import geopandas

    geoms = city(200, seed=9)
    s = geopandas.GeoSeries(geoms, index=range(1000, 1200))
    r1 = groundplan.union(s)
    r2 = groundplan.union([g.wkb for g in geoms])
    assert r1.members == r2.members
    assert max(max(m) for m in r1.members) == 199  # positions, not the GeoSeries' index
    check_against_geos(geoms, r1)


def test_invalid_input_becomes_problems(route):
    nan = float("nan")
    square = Polygon([(0, 0), (10, 0), (10, 10), (0, 10)])
    bowtie = Polygon([(20, 0), (30, 10), (30, 0), (20, 10)])  # self-crossing: even-odd gives two triangles
    with_nan = Polygon([(40, 0), (nan, 0), (50, 10)])
    empty = Polygon()
    line_like = Polygon([(60, 0), (70, 0), (80, 0)])  # no area
    geoms = [square, bowtie, with_nan, empty, line_like]
    r = groundplan.union(geoms)
    codes = {p["index"]: p["code"] for p in r.problems}
    assert codes.get(2) == "NOT_FINITE", r.problems
    assert 3 in codes and 4 in codes, r.problems
    assert all(set(p) == {"index", "stage", "code", "reason"} for p in r.problems)
    in_plans = sorted(m for ms in r.members for m in ms)
    assert in_plans == [0, 1, 1] or in_plans == [0, 1]
    assert all(p.is_valid for p in r.plans)
    assert sum(r.areas) == pytest.approx(100 + 2 * 25)  # the bow-tie's two triangles
    # every input is in a plan or named by a problem
    assert set(in_plans) | set(codes) == set(range(len(geoms)))


def test_multipolygon_and_holes(route):
    outer = Polygon([(0, 0), (20, 0), (20, 20), (0, 20)], [[(5, 5), (15, 5), (15, 15), (5, 15)]])
    mp = MultiPolygon([Polygon([(30, 0), (40, 0), (40, 10), (30, 10)]), Polygon([(50, 0), (60, 0), (60, 10), (50, 10)])])
    r = groundplan.union([outer, mp])
    check_against_geos([outer, mp], r)
    assert sorted(r.members) == [[0], [1], [1]]
    holes = [len(p.interiors) for p in r.plans]
    assert sorted(holes) == [0, 0, 1]


def test_not_polygonal_raises_type_error(route):
    from shapely.geometry import LineString, Point

    with pytest.raises(TypeError, match="geometry 1: a LineString"):
        groundplan.union([Polygon([(0, 0), (1, 0), (1, 1)]), LineString([(0, 0), (1, 1)])])
    with pytest.raises(TypeError, match="geometry 0"):
        groundplan.union([Point(0, 0)])
    with pytest.raises(TypeError):
        groundplan.union([None])
    with pytest.raises(ValueError, match="truncated"):
        groundplan.union([Polygon([(0, 0), (1, 0), (1, 1)]).wkb[:-3]])


def test_bad_arguments_raise_value_error():
    g = [Polygon([(0, 0), (1, 0), (1, 1)])]
    with pytest.raises(ValueError, match="threads"):
        groundplan.union(g, threads=-1)
    with pytest.raises(ValueError):
        groundplan.union(g, snap=-1)
    with pytest.raises(ValueError, match="quantum"):
        groundplan.union(g, device="quantum")


def test_level_of_detail_min_area():
    big = Polygon([(0, 0), (10, 0), (10, 10), (0, 10)])
    small = Polygon([(20, 0), (21, 0), (21, 1), (20, 1)])
    r = groundplan.union([big, small], min_area=5)
    assert r.members == [[0]]
    assert [p["index"] for p in r.problems if p["stage"] == "lod"] == [1]


def test_empty_input():
    r = groundplan.union([])
    assert r.plans == [] and r.members == [] and r.problems == []


def test_imports_and_unites_without_cuda():
    """No GPU here (CUDA_VISIBLE_DEVICES empty): the module imports and device="auto" uses the CPU."""
    code = ("import groundplan; from shapely.geometry import box; "
            "r = groundplan.union([box(0, 0, 1, 1), box(0.5, 0, 2, 1)]); assert r.members == [[0, 1]], r")
    env = dict(os.environ, CUDA_VISIBLE_DEVICES="", PYTHONPATH=str(BUILD_DIR / "python"))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    ext = [f for f in os.listdir(BUILD_DIR / "python" / "groundplan") if f.startswith("_groundplan")][0]
    ldd = subprocess.run(["ldd", str(BUILD_DIR / "python" / "groundplan" / ext)], capture_output=True, text=True).stdout
    assert "libcuda.so" not in ldd  # the driver library is loaded at run time, only where a GPU is asked for


def test_help_shows_signature_and_docstring():
    import inspect
    import pydoc

    text = pydoc.render_doc(groundplan.union, renderer=pydoc.plaintext)
    assert "The exact union of polygons" in text and "progress(fraction, message)" in text and "members" in text
    sig = inspect.signature(groundplan.union)
    assert sig.parameters["threads"].kind is inspect.Parameter.KEYWORD_ONLY
    assert "UnionResult" in str(sig.return_annotation)


def _wkb_route(monkeypatch):
    monkeypatch.setattr(groundplan, "_geos_addresses", lambda geoms: None)


def test_geos_route_plans_equal_the_wkb_route_exactly(monkeypatch):
    """The plans made as GEOS polygons in C++ (wrapped by Shapely 1.8's classes, or by Shapely 2's C API)
    have the very coordinates of the WKB route's."""
    if not groundplan._shares_geos():
        pytest.skip("this Shapely has a libgeos_c of its own: the WKB route only")
    geoms = block_city(3000, seed=7) + [Polygon([(0, 0), (20, 0), (20, 20), (0, 20)], [[(5, 5), (15, 5), (15, 15), (5, 15)]])]
    a = groundplan.union(geoms)
    assert a.timings["route"] == "geos"
    _wkb_route(monkeypatch)
    b = groundplan.union(geoms)
    assert b.timings["route"] == "wkb"
    assert a.members == b.members
    assert [p.wkb for p in a.plans] == [p.wkb for p in b.plans]
    assert any(len(p.interiors) for p in a.plans)
    assert all(type(p) is Polygon and p.is_valid and not p.is_empty and not p.has_z for p in a.plans)


def test_geos_route_plans_own_their_geometries(monkeypatch):
    """Each plan's GEOS polygon is freed (once) by Shapely when the plan goes, and only then."""
    import gc

    import shapely

    if shapely.__version__ >= "2":
        pytest.skip("Shapely 1.x's wrapping (Shapely 2's C API frees what it did not take over itself)")
    from shapely.geometry.base import BaseGeometry

    r = groundplan.union(city(300, seed=3))
    assert r.timings["route"] == "geos"
    addresses = [p.__geom__ for p in r.plans]
    assert len(set(addresses)) == len(addresses) and all(addresses)
    freed = []
    real = BaseGeometry._lgeos

    class Recorder:
        def __getattr__(self, name):
            return getattr(real, name)

        def GEOSGeom_destroy(self, g):
            freed.append(g)
            real.GEOSGeom_destroy(g)

    monkeypatch.setattr(BaseGeometry, "_lgeos", Recorder())
    plans = r.plans
    del r
    gc.collect()
    assert freed == []  # still held by `plans`
    del plans
    gc.collect()
    assert sorted(freed) == sorted(addresses)


def test_geos_route_frees_what_no_plan_took(monkeypatch):
    """A failure while the plans become Shapely objects frees the GEOS polygons not yet taken over."""
    import shapely

    if shapely.__version__ >= "2":
        pytest.skip("Shapely 1.x's wrapping (Shapely 2's C API frees what it did not take over itself)")
    made, destroyed = [], []
    real_destroy = groundplan._groundplan.destroy_geos
    real_make = groundplan._shapely1_polygon_maker()

    def maker():
        def make(address):
            if len(made) == 2:
                raise MemoryError("made to fail")
            made.append(address)
            return real_make(address)

        return make

    def destroy(addresses):
        destroyed.extend(addresses)
        real_destroy(addresses)

    monkeypatch.setattr(groundplan, "_shapely1_polygon_maker", maker)
    monkeypatch.setattr(groundplan._groundplan, "destroy_geos", destroy)
    geoms = [Polygon([(10 * i, 0), (10 * i + 5, 0), (10 * i + 5, 5)]) for i in range(6)]
    with pytest.raises(MemoryError):
        groundplan.union(geoms)
    assert len(made) == 2 and len(destroyed) == 4
    assert not set(made) & set(destroyed)
