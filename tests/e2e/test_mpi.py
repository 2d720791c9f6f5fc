# SPDX-License-Identifier: MIT
"""Issue 15 stage 2: `mpirun -np N groundplan ...` spreads the tiled run over N ranks (a contiguous run of tiles
each, balanced by bytes; seams reduced by a tree of rank pairs; rank 0 writes the one dataset). The plans, members
and problems must be those of the one-process run (as test_tiles.py compares them: exact ring cycles), for every
N; no plan split at a tile edge (no two plans share more than corner points), every plan GEOS-valid, nothing lost (buildings = member rows
+ dropped). A bad tile is a problem and the run completes; a rank that dies ends the run with a message and no
dataset. Skipped when the build has no MPI or mpirun is missing."""
import atexit
import json
import math
import os
import shutil
import subprocess
import tempfile

import pytest
from osgeo import ogr

from conftest import BIN, SHARED_DATA, gdal_env, run
from test_tiles import COURTYARDS, ROW, generated_city, outputs

NIEDERSACHSEN = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"


def mpi_build():
    if shutil.which("mpirun") is None:
        return False
    p = subprocess.run([BIN, "--version"], capture_output=True, text=True, env=gdal_env())
    return "MPI:" in p.stdout


pytestmark = pytest.mark.skipif(not mpi_build(), reason="no MPI in this build, or no mpirun")


# Open MPI keeps each job's session folder in <base>/ompi.<host>.<uid>/, and an mpirun that ends removes that folder
# when it is empty. Two test processes side by side (e2e_mpi and e2e_postgis under ctest -j2) could race there: a clean
# clone's CI once failed with "A call to mkdir was unable to create the desired directory: /tmp/ompi.vm.0/pid.N".
# A base folder of this process's own keeps them apart.
_OMPI_BASE = tempfile.mkdtemp(prefix="groundplan-ompi-")
atexit.register(shutil.rmtree, _OMPI_BASE, True)


def mpirun(n):
    # As root in CI and containers; more ranks than cores on a small machine.
    return ["mpirun", "--allow-run-as-root", "--oversubscribe", "--mca", "orte_tmpdir_base", _OMPI_BASE, "-np", str(n)]


def check_plans(result, stats, ranks, tiles):
    """Every plan GEOS-valid, no two plans share an edge (none split at a tile edge), nothing lost, the run's
    shape."""
    plans = [ogr.CreateGeometryFromWkt("POLYGON (" + ",".join(
        "(" + ",".join(ring) + "," + ring[0] + ")" for ring in (p[0][0], *p[0][1])) + ")") for p in result[0]]
    assert all(g.IsValid() for g in plans)
    boxes = [g.GetEnvelope() for g in plans]  # minx, maxx, miny, maxy
    order = sorted(range(len(plans)), key=lambda i: boxes[i][0])
    for a, i in enumerate(order):
        for j in order[a + 1:]:
            if boxes[j][0] > boxes[i][1]:
                break
            # Buildings touching at a corner only stay apart (one plan would not be a valid polygon); a plan split
            # at a tile edge would share a line with its other part.
            if plans[i].Intersects(plans[j]):
                assert plans[i].Intersection(plans[j]).GetDimension() <= 0, "two plans share an edge: one was split"
    c = stats["counts"]
    assert c["buildings"] == c["footprints"] + c["dropped"]
    assert len(result[1]) == c["footprints"]  # every footprint is a member of one plan
    assert sorted({m[1] for m in result[1]}) == list(range(1, c["footprints"] + 1))
    if ranks > 1:
        m = stats["mpi"]
        assert m["ranks"] == ranks
        assert m["reduce_rounds"] == math.ceil(math.log2(ranks))
        assert sum(r["tiles"] for r in m["per_rank"]) == tiles
        assert sum(r["footprints"] for r in m["per_rank"]) == c["footprints"]
        if tiles >= ranks:
            assert all(r["tiles"] >= 1 for r in m["per_rank"])
    else:
        assert "mpi" not in stats


@pytest.fixture(scope="module")
def city(tmp_path_factory):
    folder = tmp_path_factory.mktemp("mpi") / "city"
    tiles = generated_city(folder)
    return folder, tiles


@pytest.fixture(scope="module")
def city_one(city, tmp_path_factory):
    return outputs(tmp_path_factory.mktemp("one"), "one", city[0], "--tiles", "off", "--id-field", "bid")


@pytest.mark.parametrize("ranks", [1, 2, 3, 4])
def test_generated_city_over_ranks(tmp_path, city, city_one, ranks):
    folder, tiles = city
    got = outputs(tmp_path, "mpi", folder, "--tiles", "on", "--id-field", "bid", launcher=mpirun(ranks))
    assert len(got[0]) == COURTYARDS + 1
    assert got[0] == city_one[0], "plans differ from the one-process run"
    assert got[1] == city_one[1], "plan members differ"
    assert got[2] == city_one[2], "problems differ"
    assert sum(1 for p in got[0] if len(p[0][1]) == 1) == COURTYARDS
    assert max(int(p[1]) for p in got[0]) == ROW
    check_plans(got, got[3], ranks, tiles)
    t = got[3]["tiles"]
    assert t["tiles"] == tiles == 9
    assert t["final_at_once"] + t["seam_plans"] == t["tile_plans"]
    assert t["final_at_once"] + t["plans_from_seams"] == len(got[0])
    assert t["seam_plans"] > 0


def test_progress_over_ranks_counts_every_ranks_bytes(tmp_path, city):
    """-progress under mpirun: rank 0 shows it, and its reading part counts the bytes every other rank says it read
    (MPI words of their own, TileExchange::tell_progress): --stats "mpi" progress_bytes_heard is exactly the other
    ranks' bytes. The run ends as a plain one does."""
    folder, _ = city
    stats = tmp_path / "s.json"
    p = run([*mpirun(4), BIN, "-progress", "--threads", "1", "--stats", stats, "--tiles", "on", "--id-field", "bid",
             "-f", "GPKG", tmp_path / "p.gpkg", folder])
    # GDAL's progress from rank 0 alone: the run's, then the GeoPackage write's
    assert p.stdout.startswith("0...10...20...") and p.stdout.count("100 - done") == 2, p.stdout
    st = json.loads(stats.read_text())["mpi"]
    others = sum(r["bytes"] for r in st["per_rank"][1:])
    assert others > 0
    assert st["progress_bytes_heard"] == others


def test_mpirun_without_tiles_on_takes_the_tiled_run(tmp_path, city, city_one):
    """Under mpirun with several ranks --tiles auto means the ranks share the tiled run."""
    folder, tiles = city
    got = outputs(tmp_path, "auto", folder, "--id-field", "bid", launcher=mpirun(2))
    assert got[0] == city_one[0]
    assert got[3]["mpi"]["ranks"] == 2


def test_real_niedersachsen_tiles_over_4_ranks(tmp_path):
    one = outputs(tmp_path, "one", NIEDERSACHSEN, "--tiles", "off")
    got = outputs(tmp_path, "mpi", NIEDERSACHSEN, "--tiles", "on", launcher=mpirun(4))
    assert len(one[0]) > 100
    assert got[0] == one[0], "plans differ from the one-process run"
    assert got[1] == one[1], "plan members differ"
    assert got[2] == one[2], "problems differ"
    check_plans(got, got[3], 4, 4)


def test_a_bad_tile_is_a_problem_and_the_run_completes(tmp_path):
    folder = tmp_path / "tiles"
    folder.mkdir()
    for tile in sorted(NIEDERSACHSEN.glob("*.gml")):
        (folder / tile.name).symlink_to(tile)
    # last by name: the last rank's only tile, so its problem has to travel to rank 0
    bad = '<?xml version="1.0"?>\n<CityModel><cityObjectMember><bldg'
    (folder / "LoD1_99999999_broken.gml").write_text(bad)
    one = outputs(tmp_path, "one", folder, "--tiles", "off")
    got = outputs(tmp_path, "mpi", folder, "--tiles", "on", launcher=mpirun(3))
    assert got[3]["mpi"]["per_rank"][2]["bytes"] == len(bad)
    assert got[0] == one[0] and got[1] == one[1] and got[2] == one[2]
    assert [p for p in got[2] if p[2] == "UNREADABLE_FILE"], got[2]
    check_plans(got, got[3], 3, 5)


@pytest.mark.parametrize("how", ["throw", "kill", "throw@end", "kill@end"])
def test_a_rank_that_dies_aborts_the_run_and_writes_nothing(tmp_path, city, how):
    """Rank 2 fails after the map, or rank 0 at the final barrier, when it has written (@end): non-zero exit, a
    message, and no dataset under the name asked for (rank 0 writes into a hidden staging folder moved into place
    after the barrier: removed when it throws, left when it is killed, never out.gpkg)."""
    folder, _ = city
    out = tmp_path / "out.gpkg"
    env = gdal_env()
    rank = 0 if how.endswith("@end") else 2
    env["GROUNDPLAN_MPI_TEST_FAIL"] = f"{rank}:{how}"
    p = subprocess.run([*mpirun(4), "-x", "GROUNDPLAN_MPI_TEST_FAIL", BIN, "-q", "--tiles", "on", "--id-field", "bid",
                        "-f", "GPKG", str(out), str(folder)], capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode != 0
    if how.startswith("throw"):
        assert f"rank {rank} of 4: GROUNDPLAN_MPI_TEST_FAIL" in p.stderr and "aborting every rank" in p.stderr, p.stderr
    else:
        assert f"rank {rank}" in p.stderr and "signal 9" in p.stderr, p.stderr
    assert not out.exists()
    left = os.listdir(tmp_path)
    if how == "kill@end":  # killed with the dataset written in the staging folder: that folder is all there is
        assert len(left) == 1 and left[0].startswith(".groundplan-partial-"), left
        assert os.listdir(tmp_path / left[0]) == ["out.gpkg"]
    else:
        assert left == []


def test_what_the_tiled_run_cannot_do_is_refused_over_ranks(tmp_path, city):
    folder, _ = city
    p = run([*mpirun(2), BIN, "--tiles", "off", "-f", "CSV", tmp_path / "x", folder], check=False)
    assert p.returncode != 0 and "--tiles off" in p.stderr and "without mpirun" in p.stderr, p.stderr
    assert not (tmp_path / "x").exists()


def test_one_rank_without_mpirun_is_the_plain_cli(tmp_path, city, city_one):
    """An MPI build started without mpirun never starts MPI: the same output as before, no "mpi" stats."""
    folder, _ = city
    got = outputs(tmp_path, "plain", folder, "--tiles", "on", "--id-field", "bid")
    assert got[0] == city_one[0]
    assert "mpi" not in got[3]


# NRW-like tiles (issue 15 stage 3): North Rhine-Westphalia publishes LoD2 CityGML in 1 km tiles named
# LoD2_32_<km east>_<km north>_1_NW.gml (EPSG:25832 with DHHN2016 heights). Generated here: 3 x 3 tiles, courtyard
# blocks (60 m, the yard a hole) on a 500 m pitch, those at x or y = 970 and 1970 crossing the 1 km edges (one at
# each inner tile corner, in four tiles), and two rows of 12 touching houses across the edges x = 1000 and 2000;
# every building a LoD2 box (ground, roof, walls) in the tile of its centre.
NRW_EAST, NRW_NORTH = 350000, 5660000
NRW_BLOCKS = 25
NRW_ROW = 12


def lod2_box(bid, x0, y0, x1, y1, height):
    def ring(pts):
        pts = pts + [pts[0]]
        return ("<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">"
                + " ".join(f"{x:.3f} {y:.3f} {z:.3f}" for x, y, z in pts)
                + "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>")

    x0, y0, x1, y1 = NRW_EAST + x0, NRW_NORTH + y0, NRW_EAST + x1, NRW_NORTH + y1
    z0, z1 = 60.0, 60.0 + height
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    surfaces = [("GroundSurface", ring([(x, y, z0) for x, y in reversed(corners)])),
                ("RoofSurface", ring([(x, y, z1) for x, y in corners]))]
    for (xa, ya), (xb, yb) in zip(corners, corners[1:] + corners[:1]):
        surfaces.append(("WallSurface", ring([(xa, ya, z0), (xb, yb, z0), (xb, yb, z1), (xa, ya, z1)])))
    bounded = "".join(f"<bldg:boundedBy><bldg:{kind}><bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>"
                      f"{poly}</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface></bldg:{kind}>"
                      "</bldg:boundedBy>" for kind, poly in surfaces)
    return (f"<core:cityObjectMember><bldg:Building gml:id=\"{bid}\"><bldg:measuredHeight uom=\"urn:adv:uom:m\">"
            f"{height}</bldg:measuredHeight>{bounded}</bldg:Building></core:cityObjectMember>\n")


def nrw_like_tiles(folder):
    buildings = []
    for i in range(1, 6):
        for j in range(1, 6):
            x0, y0 = 500 * i - 30, 500 * j - 30
            buildings += [(x0, y0, x0 + 60, y0 + 16), (x0, y0 + 44, x0 + 60, y0 + 60),
                          (x0, y0 + 16, x0 + 16, y0 + 44), (x0 + 44, y0 + 16, x0 + 60, y0 + 44)]
    for start in (880, 1880):
        buildings += [(start + 20 * k, 1700, start + 20 * k + 20, 1712) for k in range(NRW_ROW)]
    tiles = {}
    for n, (x0, y0, x1, y1) in enumerate(buildings):
        key = (int((x0 + x1) / 2 // 1000), int((y0 + y1) / 2 // 1000))
        tiles.setdefault(key, []).append(lod2_box(f"DENW{n:012d}", x0, y0, x1, y1, 8 + n % 7))
    folder.mkdir()
    head = ('<?xml version="1.0" encoding="UTF-8"?>\n<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" '
            'xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml">\n'
            '<gml:boundedBy><gml:Envelope srsName="urn:adv:crs:ETRS89_UTM32*DE_DHHN2016_NH" srsDimension="3">'
            '<gml:lowerCorner>{} {} 0</gml:lowerCorner><gml:upperCorner>{} {} 100</gml:upperCorner>'
            '</gml:Envelope></gml:boundedBy>\n')
    for (tx, ty), members in sorted(tiles.items()):
        e, n = NRW_EAST // 1000 + tx, NRW_NORTH // 1000 + ty
        (folder / f"LoD2_32_{e}_{n}_1_NW.gml").write_text(
            head.format(e * 1000, n * 1000, e * 1000 + 1000, n * 1000 + 1000) + "".join(members) + "</core:CityModel>\n")
    return len(tiles), len(buildings)


def test_nrw_like_tiles_over_4_ranks(tmp_path):
    """Stage 3: the NRW-like folder over 4 ranks gives the one-process plans."""
    folder = tmp_path / "nrw"
    tiles, buildings = nrw_like_tiles(folder)
    assert tiles == 9
    one = outputs(tmp_path, "one", folder, "--tiles", "off")
    got = outputs(tmp_path, "mpi", folder, "--tiles", "on", launcher=mpirun(4))
    assert got[0] == one[0], "plans differ from the one-process run"
    assert got[1] == one[1], "plan members differ"
    assert got[2] == one[2], "problems differ"
    # the generator's own count: a plan a block (its yard a hole) and one a row; every building a footprint
    assert len(got[0]) == NRW_BLOCKS + 2
    assert sum(1 for p in got[0] if len(p[0][1]) == 1) == NRW_BLOCKS
    assert sorted(int(p[1]) for p in got[0])[-2:] == [NRW_ROW, NRW_ROW]
    assert got[3]["counts"]["footprints"] == buildings
    assert got[3]["tiles"]["seam_plans"] > 0
    check_plans(got, got[3], 4, tiles)


# A new GeoPackage under mpirun (driver/output/gpkg_rank_slices.h): every rank writes its own final plans into a slice
# beside rank 0's staged destination, and rank 0 appends the slices in FID order. The file must be the one rank 0
# writes when it gathers every plan (forced here by -dim XY, an option that changes nothing in these 2D plans but
# keeps one writer), in every respect test_gpkg_writers.py compares; and as sets, the plans of one process.
GPKG_LAYERS = ["ground_plans", "plan_members", "problems"]


def gpkg_run(tmp_path, name, src, ranks, *extra, env=None, check=True, layers=GPKG_LAYERS):
    out, stats = tmp_path / f"{name}.gpkg", tmp_path / f"{name}.json"
    p = subprocess.run([*mpirun(ranks), *(["-x", "GROUNDPLAN_MPI_TEST_FAIL"] if env else []), BIN, "-q", "--threads", "1", "--tiles", "on",
                        "--id-field", "bid", "--stats", str(stats), *extra, "-f", "GPKG", str(out), str(src),
                        *layers], capture_output=True, text=True, env=env or gdal_env(), timeout=300)
    if check:
        assert p.returncode == 0, p.stderr
        return out, json.loads(stats.read_text())
    return p


def same_gpkg(a, b):
    """test_gpkg_writers.py's comparison; a table without rows (GDAL leaves its feature_count NULL, which that
    comparison's count check does not take) is compared here: schema and gpkg_contents there, no row in either."""
    import sqlite3
    from test_gpkg_writers import same_file_content
    empty = [t for t in GPKG_LAYERS if sqlite3.connect(b).execute(f'SELECT count(*) FROM "{t}"').fetchone()[0] == 0]
    for t in empty:
        assert list(sqlite3.connect(a).execute(f'SELECT * FROM "{t}"')) == [], t
    same_file_content(a, b, [t for t in GPKG_LAYERS if t not in empty])


def plan_rows(path):
    import sqlite3
    db = sqlite3.connect(path)
    return (sorted(db.execute("SELECT n_parts, area_m2, min_z, max_z, building_ids FROM ground_plans")),
            sorted(db.execute("SELECT fp_id, source_id FROM plan_members")),
            sorted(db.execute("SELECT source_id, stage, code, reason FROM problems")))


def test_gpkg_written_by_every_rank_is_the_gathered_file(tmp_path, city):
    import sqlite3
    folder, _ = city
    (tmp_path / "ranks").mkdir()
    (tmp_path / "gathered").mkdir()
    ranks, stats = gpkg_run(tmp_path / "ranks", "out", folder, 4)
    gathered, g_stats = gpkg_run(tmp_path / "gathered", "out", folder, 4, "-dim", "XY")
    w = stats["writer"]
    assert w["writers"] == 4 and w["by"] == "every rank, a slice each", w
    assert g_stats["writer"]["rank_0_writes_every_plan"] == "ogr2ogr option -dim", g_stats["writer"]
    plans = stats["counts"]["ground_plans"]
    assert plans == COURTYARDS + 1 == g_stats["counts"]["ground_plans"]
    assert stats["tiles"]["seam_plans"] > 0
    same_gpkg(ranks, gathered)
    db = sqlite3.connect(ranks)
    assert db.execute("SELECT count(*) FROM ground_plans").fetchone()[0] == plans
    assert db.execute("SELECT count(*) FROM plan_members").fetchone()[0] == stats["counts"]["footprints"]
    assert db.execute("SELECT count(*) FROM rtree_ground_plans_geom").fetchone()[0] == plans
    assert db.execute("SELECT rtreecheck('rtree_ground_plans_geom')").fetchone()[0] == "ok"
    assert sorted(os.listdir(tmp_path / "ranks")) == ["out.gpkg", "out.json"], "a slice or a marker was left behind"
    # as sets, the plans, members and problems of one process
    (tmp_path / "one").mkdir()
    run([BIN, "-q", "--tiles", "off", "--id-field", "bid", "-f", "GPKG", tmp_path / "one" / "out.gpkg", folder,
         *GPKG_LAYERS])
    assert plan_rows(ranks) == plan_rows(tmp_path / "one" / "out.gpkg")


def test_gpkg_by_ranks_on_the_real_niedersachsen_tiles_and_a_bad_one(tmp_path):
    """Real tiles and ids, 3 ranks for 5 tiles, the last one broken: its problem (rank 2's) is in rank 0's layer."""
    folder = tmp_path / "tiles"
    folder.mkdir()
    for tile in sorted(NIEDERSACHSEN.glob("*.gml")):
        (folder / tile.name).symlink_to(tile)
    (folder / "LoD1_99999999_broken.gml").write_text('<?xml version="1.0"?>\n<CityModel><cityObjectMember><bldg')
    (tmp_path / "ranks").mkdir()
    (tmp_path / "gathered").mkdir()
    ranks, stats = gpkg_run(tmp_path / "ranks", "out", folder, 3)
    gathered, _ = gpkg_run(tmp_path / "gathered", "out", folder, 3, "-dim", "XY")
    assert stats["writer"]["writers"] == 3
    assert stats["counts"]["ground_plans"] > 100
    assert stats["counts"]["problems"] >= 1
    same_gpkg(ranks, gathered)
    assert [p for p in plan_rows(ranks)[2] if p[2] == "UNREADABLE_FILE"]


def test_gpkg_by_ranks_with_a_new_name(tmp_path, city):
    """-nln names the plans table: the ranks' slices are appended to it."""
    import sqlite3
    from test_gpkg_writers import same_file_content
    folder, _ = city
    (tmp_path / "ranks").mkdir()
    (tmp_path / "gathered").mkdir()
    ranks, stats = gpkg_run(tmp_path / "ranks", "out", folder, 4, "-nln", "blocks", layers=["ground_plans"])
    gathered, _ = gpkg_run(tmp_path / "gathered", "out", folder, 4, "-nln", "blocks", "-dim", "XY",
                           layers=["ground_plans"])
    assert stats["writer"]["writers"] == 4
    same_file_content(ranks, gathered, ["blocks"])
    assert sqlite3.connect(ranks).execute("SELECT count(*) FROM blocks").fetchone()[0] == COURTYARDS + 1


def test_ranks_that_do_not_share_the_folder_let_rank_0_write(tmp_path, city):
    """A rank that does not see the destination's folder (no shared file system: pretended by the test hook, as one
    host cannot make it) could not hand rank 0 its slice: rank 0 gathers every plan and writes them, as --stats
    says; the file is the gathered one."""
    folder, _ = city
    env = gdal_env()
    env["GROUNDPLAN_MPI_TEST_FAIL"] = "2:pretend@shared"
    (tmp_path / "blind").mkdir()
    (tmp_path / "gathered").mkdir()
    got, stats = gpkg_run(tmp_path / "blind", "out", folder, 4, env=env)
    gathered, _ = gpkg_run(tmp_path / "gathered", "out", folder, 4, "-dim", "XY")
    assert stats["writer"]["rank_0_writes_every_plan"] == \
        "the destination's folder is not seen by rank 2 (not a file system every rank shares)", stats["writer"]
    same_gpkg(got, gathered)
    assert sorted(os.listdir(tmp_path / "blind")) == ["out.gpkg", "out.json"], "the marker was left behind"


@pytest.mark.parametrize("how", ["throw@slice", "kill@slice"])
def test_a_rank_failing_in_its_gpkg_slice_leaves_no_destination(tmp_path, city, how):
    """Rank 2 fails once it has written its slice. Thrown: every rank learns it, the destination and every slice
    are removed, the run fails naming rank 2; nothing is left. Killed: mpirun ends the run; at most rank 0's hidden
    staging folder is left, never out.gpkg, a slice or the shared-folder marker beside it."""
    folder, _ = city
    env = gdal_env()
    env["GROUNDPLAN_MPI_TEST_FAIL"] = f"2:{how}"
    p = gpkg_run(tmp_path, "out", folder, 4, env=env, check=False)
    assert p.returncode != 0
    assert not (tmp_path / "out.gpkg").exists()
    left = sorted(os.listdir(tmp_path))
    if how.startswith("throw"):
        assert "could not write" in p.stderr and "rank 2: GROUNDPLAN_MPI_TEST_FAIL" in p.stderr, p.stderr
        assert left == [], left
    else:
        assert "rank 2" in p.stderr and "signal 9" in p.stderr, p.stderr
        assert all(n.startswith(".groundplan-partial-") for n in left), left


def test_ranks_share_the_hosts_cores_without_threads(tmp_path, city):
    """Without --threads each rank takes its share of the host's cores (the ranks on one host divide them), not
    all of them: N ranks do not start N x cores threads. --threads still sets it. Unbound ranks (--bind-to none), so
    that every rank sees every core."""
    folder = city[0]
    usable, host = len(os.sched_getaffinity(0)), os.cpu_count()
    expected = usable if usable < host else max(1, usable // 2)
    for flags, threads in (([], expected), (["--threads", "3"], 3)):
        stats = tmp_path / f"s{len(flags)}.json"
        run([*mpirun(2), "--bind-to", "none", BIN, "-q", "--stats", stats, *flags, "--tiles", "on", "-f", "GPKG",
             tmp_path / f"o{len(flags)}.gpkg", folder])
        assert json.loads(stats.read_text())["reading"]["threads"] == threads, flags
