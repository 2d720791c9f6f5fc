# SPDX-License-Identifier: MIT
"""groundplan: ground plans (the exact union of building footprints) from Python.

Two functions:

* :func:`union` -- the exact union of Shapely polygons (a list, or a GeoSeries), with the members of
  every plan and the problems the engine found.
* :func:`read` -- the whole pipeline on any input the ``groundplan`` command takes (CityGML, CityJSON,
  KML/KMZ+COLLADA, glTF, any OGR layer): plans, footprints and problems as GeoDataFrames.

Both release the GIL while they work; Ctrl-C cancels them (KeyboardInterrupt), and so does a ``progress``
callback that returns ``False`` (:class:`Cancelled`) or raises (its exception). Errors carry the messages of
the command line tool: a bad argument is a ``ValueError``, an unreadable input an ``OSError``.

From a source build: ``PYTHONPATH=build/python python3 -c "import groundplan"``.
"""
from __future__ import annotations

import os
import time
from typing import Any, Callable, Dict, Iterable, List, NamedTuple, Optional, Sequence, Union

from . import _groundplan
from ._groundplan import Cancelled

__all__ = ["union", "verify", "read", "UnionResult", "ReadResult", "Cancelled"]

ProgressCallback = Callable[[float, str], Optional[bool]]


class UnionResult(NamedTuple):
    """What :func:`union` gives back.

    plans:    one Shapely Polygon per connected region of the union (outer ring counter-clockwise, holes
              clockwise, valid), in no particular order.
    members:  for each plan, the positions (0-based, in input order) of the input geometries it is made of.
    areas:    for each plan, its area (input units squared).
    problems: input geometries that are in no plan, and notes, as dicts with the keys
              ``index`` (the input position, or None), ``stage``, ``code`` (e.g. ``NOT_FINITE``, ``NO_AREA``)
              and ``reason``.
    timings:  seconds spent in each step, wall clock (``*_s``) and CPU time of the whole process
              (``*_cpu_s``): ``to_wkb`` (Shapely -> WKB bytes or GEOS addresses, Python), ``parse`` (-> the
              engine's footprints, C++; ``parse_alloc_s`` of it allocating them), ``union``, ``write`` (plans ->
              GEOS polygons or WKB, C++), ``to_python`` (the Python lists), ``from_wkb`` (-> Shapely polygons,
              Python), ``call`` and ``total``; ``parse_minor_faults`` and ``union_minor_faults`` (page faults:
              a process's first call pays for fresh memory); ``route``: "geos" where Shapely's libgeos_c is
              this module's (Debian's Shapely 1.8, or a Shapely 2 built against the system GEOS: geometries
              cross as GEOS pointers both ways), else "wkb" (e.g. a Shapely 2 wheel, which brings its own GEOS).
    """

    plans: List[Any]
    members: List[List[int]]
    areas: List[float]
    problems: List[Dict[str, Any]]
    timings: Dict[str, Any]


class ReadResult(NamedTuple):
    """What :func:`read` gives back: the CLI's three layers.

    With GeoPandas installed, ``plans`` and ``footprints`` are GeoDataFrames with the working CRS set and
    ``problems`` is a pandas DataFrame (it has no geometry, as ``geopandas.read_file`` gives for such a
    layer). Without GeoPandas each is a list of dicts, one per feature, the geometry under ``"geometry"``
    as a Shapely geometry (or WKB bytes without Shapely).

    plans:      gp_id, n_parts, area_m2, min_z, max_z, building_ids (the members' ids), buildings (their
                Buildings' ids, each once: a BuildingPart's Building), geometry (Polygon)
    footprints: fp_id, source_id, source_file, method, gp_id (None when in no plan), min_z, max_z (metres),
                building_id (the Building of a BuildingPart, else source_id), geometry (MultiPolygon)
    problems:   source_id, file, stage, code, reason
    crs:        the working CRS as WKT (empty when the input has none)
    stats:      buildings read and dropped, blocks, backend, seconds per stage
    """

    plans: Any
    footprints: Any
    problems: Any
    crs: str
    stats: Dict[str, Any]


_SHAPELY_MAJOR: Optional[int] = None


def _shapely_major() -> int:
    global _SHAPELY_MAJOR
    if _SHAPELY_MAJOR is None:
        import shapely

        _SHAPELY_MAJOR = int(shapely.__version__.split(".")[0])
    return _SHAPELY_MAJOR


def _to_wkb(geometries: Iterable[Any]) -> List[bytes]:
    """Shapely geometries (a sequence, GeoSeries or array) -> a list of WKB bytes, vectorised where Shapely can."""
    if hasattr(geometries, "geom_type") and hasattr(geometries, "values"):  # GeoSeries: its positions, not its index
        geometries = list(geometries.values)
    geometries = list(geometries)
    if all(isinstance(g, (bytes, bytearray)) for g in geometries):  # WKB already
        return [bytes(g) for g in geometries]
    if _shapely_major() >= 2:
        import numpy as np
        import shapely

        # np.fromiter: np.asarray probes each object for the sequence protocol (35 ms for 60k geometries)
        if isinstance(geometries, np.ndarray):
            arr = geometries
        else:
            try:
                arr = np.fromiter(geometries, dtype=object, count=len(geometries))
            except (TypeError, ValueError):  # NumPy < 1.23 has no object dtype in fromiter
                arr = np.asarray(geometries, dtype=object)
        return list(shapely.to_wkb(arr, output_dimension=2))
    out = []
    for i, g in enumerate(geometries):
        if isinstance(g, (bytes, bytearray)):
            out.append(bytes(g))
            continue
        try:
            out.append(g.wkb)
        except AttributeError:
            raise TypeError(f"geometry {i}: expected a Shapely geometry or WKB bytes, got {type(g).__name__}") from None
    return out


_SHARES_GEOS: Optional[bool] = None


def _shares_geos() -> bool:
    """Whether Shapely's libgeos_c is the very library this module links (same address of GEOSversion):
    Debian's Shapely 1.8, or a Shapely 2 built against the system's GEOS (not a wheel with its own copy).
    Then geometries cross as GEOS pointers both ways, with no WKB."""
    global _SHARES_GEOS
    if _SHARES_GEOS is None:
        try:
            ours = _groundplan.geos_version_address()
            if _shapely_major() >= 2:
                import shapely.lib

                theirs = _groundplan.geos_version_address_in(shapely.lib.__file__)
            else:
                import ctypes

                from shapely.geos import lgeos

                theirs = ctypes.cast(lgeos._lgeos.GEOSversion, ctypes.c_void_p).value
            _SHARES_GEOS = bool(theirs) and ours == theirs
        except Exception:  # another Shapely layout: the WKB route
            _SHARES_GEOS = False
    return _SHARES_GEOS


def _geos_addresses(geometries: Sequence[Any]) -> Optional[List[int]]:
    """The addresses of the GEOS geometries behind `geometries` (Shapely 1.x and 2.x both expose ``_geom``),
    when Shapely's libgeos_c is the one this module links (then the engine reads them directly: 10x faster
    than ``.wkb`` on Shapely 1.8); else None (-> WKB)."""
    if not _shares_geos():
        return None
    try:
        addresses = [g._geom for g in geometries]
    except AttributeError:  # WKB bytes, None ...: the WKB route names the culprit
        return None
    if not all(type(a) is int and a for a in addresses):
        return None
    return addresses


def _shapely1_polygon_maker() -> Callable[[int], Any]:
    """Shapely 1.8: a function that makes a Shapely Polygon owning a GEOS polygon (given by its address).

    Shapely's own ``geom_factory`` asks GEOS for the type and the dimension through ctypes and sets six
    attributes through Shapely's ``__setattr__`` (about 7 us a plan); the plans are all 2D Polygons, so this
    sets what ``geom_factory`` would set (``__geom__``, ``_is_empty``, ``_ndim``; ``__p__`` and
    ``_other_owned`` keep their class defaults: no parent, owned) straight into the new object's ``__dict__``
    (about 1 us). Shapely 1.8's attributes are checked first; with another layout, ``geom_factory``."""
    from shapely.geometry import Polygon
    from shapely.geometry.base import BaseGeometry, geom_factory

    layout = all(hasattr(BaseGeometry, a) for a in ("__geom__", "__p__", "_other_owned", "_is_empty", "_ndim", "_empty"))
    if not layout or hasattr(Polygon, "__slots__") or BaseGeometry._other_owned is not False:
        return geom_factory
    new = object.__new__

    def make(address: int) -> Any:
        ob = new(Polygon)
        d = ob.__dict__
        d["__geom__"] = address
        d["_is_empty"] = False
        d["_ndim"] = 2
        return ob

    return make


def _own_geos(addresses: List[int]) -> List[Any]:
    """Shapely objects for the GEOS polygons that union_*(geos_out=True) made; frees the rest on failure."""
    if _shapely_major() >= 2:
        return _groundplan.shapely2_geometries(addresses)  # Shapely's C API; frees the rest itself
    out: List[Any] = []
    try:
        make = _shapely1_polygon_maker()
        for a in addresses:
            out.append(make(a))
    except BaseException:
        _groundplan.destroy_geos(addresses[len(out):])
        raise
    return out


def _from_wkb(wkbs: Sequence[Optional[bytes]]) -> List[Any]:
    if _shapely_major() >= 2:
        import shapely

        return list(shapely.from_wkb(wkbs))
    try:  # one reader for all (shapely.wkb.loads makes one per call)
        from shapely.geos import WKBReader, lgeos

        loads = WKBReader(lgeos).read
    except ImportError:
        from shapely.wkb import loads
    return [None if b is None else loads(b) for b in wkbs]


def union(
    geometries: Union[Sequence[Any], Any],
    *,
    threads: int = 0,
    resolution: float = 0,
    snap: float = 0,
    close_gaps: float = 0,
    simplify: float = 0,
    min_hole_area: float = 0,
    min_area: float = 0,
    device: str = "auto",
    progress: Optional[ProgressCallback] = None,
) -> UnionResult:
    """The exact union of polygons: non-overlapping ground plans, one per connected region.

    geometries: Shapely Polygons / MultiPolygons (a list, tuple, GeoSeries, or array; WKB bytes too),
        in a projected CRS (metres): the engine's tolerances (snap, close_gaps, ...) are metres.
        They may be invalid: self-crossing rings follow the even-odd rule; a geometry with NaN or infinite
        coordinates, or with no area, is reported in ``problems`` and is in no plan. A geometry of another
        type (Point, LineString) raises TypeError.
    threads: threads to use, 0 = all cores.
    resolution: pixel of the raster that groups touching footprints (metres); 0 = automatic. The result
        never depends on it.
    snap, close_gaps, simplify, min_hole_area, min_area: the level of detail of ``groundplan --snap``,
        ``--close-gaps`` ... (0 = off; docs/level_of_detail.md). With all of them 0 the result is the exact union.
    device: "auto", "cpu" or "cuda" (raster backend; "auto" is the CPU; "cuda" only when asked for).
    progress: called as ``progress(fraction, message)`` on the calling thread, with increasing fractions
        in [0, 1]; returning ``False`` cancels (:class:`Cancelled`), an exception it raises is re-raised.

    Returns a :class:`UnionResult` (plans, members, areas, problems, timings).
    Raises ValueError for bad arguments, TypeError for non-polygonal input, KeyboardInterrupt on Ctrl-C.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    if hasattr(geometries, "geom_type") and hasattr(geometries, "values"):  # GeoSeries: its positions, not its index
        geometries = list(geometries.values)
    held = geometries if isinstance(geometries, list) else list(geometries)  # alive until the engine has read them
    addresses = _geos_addresses(held)
    call = _groundplan.union_geos if addresses is not None else _groundplan.union_wkb
    data = addresses if addresses is not None else _to_wkb(held)
    t1, c1 = time.perf_counter(), time.process_time()
    r = call(
        data,
        # Shapely 1.x sharing this module's libgeos_c: the plans come back as GEOS polygons, not WKB
        geos_out=addresses is not None,
        threads=int(threads),
        resolution=float(resolution),
        device=str(device),
        snap=float(snap),
        close_gaps=float(close_gaps),
        simplify=float(simplify),
        min_hole_area=float(min_hole_area),
        min_area=float(min_area),
        progress=progress,
    )
    t2, c2 = time.perf_counter(), time.process_time()
    plans = _own_geos(r["plans"]) if addresses is not None else _from_wkb(r["plans"])
    t3, c3 = time.perf_counter(), time.process_time()
    timings = dict(r["timings"])
    timings.update(to_wkb_s=t1 - t0, from_wkb_s=t3 - t2, call_s=t2 - t1, total_s=t3 - t0,
                   to_wkb_cpu_s=c1 - c0, from_wkb_cpu_s=c3 - c2, call_cpu_s=c2 - c1, total_cpu_s=c3 - c0,
                   route="geos" if addresses is not None else "wkb")
    del held
    return UnionResult(plans, r["members"], r["areas"], r["problems"], timings)


def verify(
    geometries: Union[Sequence[Any], Any],
    plans: Optional[Sequence[Any]] = None,
    members: Optional[Sequence[Sequence[int]]] = None,
    ids: Optional[Sequence[str]] = None,
    *,
    threads: int = 0,
) -> Dict[str, Any]:
    """``groundplan --verify``: plans against GEOS's union of the same geometries, every difference decided
    exactly against the geometries (GEOS computes in floating point and can keep a tiny hole they cover, or
    close one they leave).

    geometries: the input polygons, as for :func:`union`.
    plans, members: the plans to check and, for each, the positions of its input geometries (as
        :func:`union` gives them); both None: :func:`union` of the geometries is checked.
    ids: names of the geometries for the report (default: their positions).

    Returns a dict: ``verdict`` (``"match"``, ``"match_geos_differs"`` or ``"mismatch"``), ``match`` (bool),
    ``line`` (e.g. ``"MATCH: GEOS differs in 1 place, each decided in our favour: largest 2.5e-12 m2"``, or
    ``"MISMATCH: ..."`` naming the region and the buildings), ``summary`` and the counts of ``--stats``'
    ``verify``.
    """
    if hasattr(geometries, "geom_type") and hasattr(geometries, "values"):
        geometries = list(geometries.values)
    held = geometries if isinstance(geometries, list) else list(geometries)
    if plans is None:
        r = union(held, threads=threads)
        plans, members = r.plans, r.members
    plans = list(plans)
    members = [list(m) for m in members] if members is not None else [[] for _ in plans]
    return _groundplan.verify_wkb(_to_wkb(held), _to_wkb(plans), members, [str(i) for i in ids] if ids is not None else [])


_OPTION_NAMES = {
    # keyword -> the GroundPlan driver's open option (the CLI's flags map onto the same ones)
    "threads": "NUM_THREADS",
    "resolution": "RESOLUTION",
    "resolution_mode": "RESOLUTION_MODE",
    "device": "DEVICE",
    "footprints": "FOOTPRINTS",
    "lod": "LOD",
    "t_srs": "T_SRS",
    "s_srs": "S_SRS",
    "a_srs": "A_SRS",
    "origin": "ORIGIN",
    "axis_order": "AXIS_ORDER",
    "preset": "PRESET",
    "snap": "SNAP",
    "close_gaps": "CLOSE_GAPS",
    "simplify": "SIMPLIFY",
    "min_hole_area": "MIN_HOLE_AREA",
    "min_area": "MIN_AREA",
    "input_layers": "INPUT_LAYERS",
    "input_where": "INPUT_WHERE",
    "input_sql": "INPUT_SQL",
    "input_dialect": "INPUT_DIALECT",
    "input_oo": "INPUT_OO",
    "id_field": "ID_FIELD",
    "group_by": "GROUP_BY",
}


def _option_value(value: Any) -> str:
    if isinstance(value, bool):
        return "YES" if value else "NO"
    if isinstance(value, (list, tuple)):
        return ",".join(str(v) for v in value)
    return str(value)


def read(
    path_or_paths: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    *,
    progress: Optional[ProgressCallback] = None,
    **options: Any,
) -> ReadResult:
    """Reads building models and computes their ground plans: ``groundplan`` (the CLI) as a function.

    path_or_paths: a file or folder, or a list of them: CityGML (.gml, .xml, .gz), CityJSON / CityJSONSeq,
        KML/KMZ with COLLADA, glTF/GLB, 3D Tiles (tileset.json or its folder, .b3dm, .i3dm, .cmpt), or any vector
        source OGR opens (GeoPackage, Shapefile ...).
    options: the GroundPlan driver's open options, as keywords (lower case) or as their own names:
        threads (NUM_THREADS), resolution, resolution_mode, device, footprints ("auto", "ground-surface",
        "decompose"), lod, t_srs, s_srs, a_srs, origin, axis_order, preset ("none", "cfd"), snap, close_gaps,
        simplify, min_hole_area, min_area, input_layers, input_where, input_sql, input_dialect, input_oo,
        id_field, group_by. ``ogrinfo --format GroundPlan`` lists them all.
    progress: as for :func:`union`.

    Returns a :class:`ReadResult` (plans, footprints, problems, crs, stats): GeoDataFrames when GeoPandas is
    installed, else lists of dicts. Raises OSError when no input can be read, ValueError for a bad option.
    """
    if isinstance(path_or_paths, (str, bytes, os.PathLike)):
        paths = [os.fsdecode(path_or_paths)]
    else:
        paths = [os.fsdecode(p) for p in path_or_paths]
    oo: Dict[str, str] = {}
    for key, value in options.items():
        name = _OPTION_NAMES.get(key, key.upper())
        if name not in _OPTION_NAMES.values() and key.upper() != key:
            raise TypeError(f"read() got an unexpected keyword argument '{key}'")
        oo[name] = _option_value(value)
    r = _groundplan.read(paths, oo, progress)
    layers = r["layers"]
    crs = r["crs_wkt"]
    try:
        import geopandas
        import pandas
    except ImportError:
        geopandas = None

    def records(layer: Dict[str, Any]) -> List[Dict[str, Any]]:
        cols = layer["columns"]
        n = len(next(iter(cols.values()))) if cols else 0
        geoms = layer["geometry"]
        if geoms is not None:
            try:
                geoms = _from_wkb(geoms)
            except ImportError:
                pass
        out = []
        for i in range(n):
            rec = {k: v[i] for k, v in cols.items()}
            if geoms is not None:
                rec["geometry"] = geoms[i]
            out.append(rec)
        return out

    def frame(layer: Dict[str, Any]) -> Any:
        if layer["geometry"] is None:
            return pandas.DataFrame(layer["columns"])
        geometry = geopandas.GeoSeries.from_wkb(layer["geometry"], crs=crs or None)
        return geopandas.GeoDataFrame(layer["columns"], geometry=geometry, crs=crs or None)

    convert = frame if geopandas is not None else records
    return ReadResult(
        convert(layers["ground_plans"]),
        convert(layers["footprints"]),
        convert(layers["problems"]),
        crs,
        dict(r["stats"], crs_name=r["crs_name"]),
    )
