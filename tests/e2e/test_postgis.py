# SPDX-License-Identifier: MIT
"""Issue 15 stage 5: `mpirun -np 4 groundplan ... -f PostgreSQL PG:...` into a real PostGIS server. Every rank writes
its own final plans into the tables rank 0 made, in a transaction of its own committed only once every rank has
written. The plans read back (with OGR) must be those of the one-process run (the same exact ring cycles, members,
problems), GEOS-valid, none split at a tile edge, nothing lost; gp_id and the feature ids (ogc_fid) those a run
gathering on rank 0 gives. The tables are made in a staging schema and reach the public schema only once every
rank has committed: a rank killed before leaves no table of the run there (and -overwrite leaves the old ones).

The server is Debian's postgresql + postgis, started here on a temporary folder with a local socket only (no TCP)
and stopped after; as root (CI) it runs as the postgres user. Skipped, with the reason, where the server binaries,
PostGIS, GDAL's PostgreSQL driver or (for the runs over ranks) MPI are missing."""
import csv
import glob
import json
import os
import pwd
import shutil
import subprocess
import tempfile

import pytest
from osgeo import ogr

from conftest import BIN, SHARED_DATA, gdal_env, run
from test_mpi import check_plans, mpi_build, mpirun
from test_tiles import COURTYARDS, generated_city, outputs, plan_key

NIEDERSACHSEN = SHARED_DATA / "citygml1-niedersachsen-lod1-4tiles"


def server_binaries():
    """The folder of initdb, pg_ctl and postgres (Debian keeps them out of PATH), or None."""
    for folder in sorted(glob.glob("/usr/lib/postgresql/*/bin"), reverse=True):
        if all(os.access(os.path.join(folder, b), os.X_OK) for b in ("initdb", "pg_ctl", "postgres")):
            return folder
    found = shutil.which("pg_ctl")
    return os.path.dirname(found) if found and shutil.which("initdb") else None


def missing():
    """Why the PostGIS tests cannot run here, or None."""
    if server_binaries() is None:
        return "no PostgreSQL server binaries (Debian: postgresql)"
    if shutil.which("psql") is None:
        return "no psql (Debian: postgresql-client)"
    if not glob.glob("/usr/share/postgresql/*/extension/postgis.control"):
        return "no PostGIS extension (Debian: postgresql-15-postgis-3)"
    if ogr.GetDriverByName("PostgreSQL") is None:
        return "GDAL has no PostgreSQL driver"
    if os.geteuid() == 0:
        try:
            pwd.getpwnam("postgres")
        except KeyError:
            return "running as root and there is no postgres user to run the server as"
    return None


pytestmark = pytest.mark.skipif(missing() is not None, reason=str(missing()))


class Server:
    """A PostgreSQL server on a temporary folder, reachable only through a Unix socket in that folder."""

    def __init__(self):
        self.dir = tempfile.mkdtemp(prefix="gp-pg-")  # short: a socket path has at most 107 characters
        self.bin = server_binaries()
        self.as_user = []
        if os.geteuid() == 0:  # initdb and postgres refuse root
            user = pwd.getpwnam("postgres")
            os.chown(self.dir, user.pw_uid, user.pw_gid)
            self.as_user = ["runuser", "-u", "postgres", "--"]
        self.data = os.path.join(self.dir, "data")
        self.server([f"{self.bin}/initdb", "-D", self.data, "-A", "trust", "-U", "postgres", "-E", "UTF8"])
        self.server([f"{self.bin}/pg_ctl", "-D", self.data, "-l", os.path.join(self.dir, "log"), "-w", "-t", "60",
                     "-o", f"-k {self.dir} -c listen_addresses='' -c fsync=off", "start"])
        self.databases = 0
        self.psql("postgres", "CREATE DATABASE gp_template")
        self.psql("gp_template", "CREATE EXTENSION postgis")

    def server(self, args):
        p = subprocess.run(self.as_user + args, capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, f"{' '.join(args)}: {p.stdout}\n{p.stderr}"

    def psql(self, db, sql):
        p = subprocess.run(["psql", "-h", self.dir, "-U", "postgres", "-d", db, "-v", "ON_ERROR_STOP=1", "-At",
                            "-c", sql], capture_output=True, text=True, timeout=60)
        assert p.returncode == 0, f"{sql}: {p.stderr}"
        return p.stdout.strip()

    def new_database(self):
        """A fresh database with PostGIS; its OGR connection string."""
        self.databases += 1
        name = f"gp{self.databases}"
        self.psql("postgres", f"CREATE DATABASE {name} TEMPLATE gp_template")
        return name, f"PG:host={self.dir} dbname={name} user=postgres"

    def stop(self):
        subprocess.run(self.as_user + [f"{self.bin}/pg_ctl", "-D", self.data, "-m", "immediate", "-w", "stop"],
                       capture_output=True, timeout=120)
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture(scope="module")
def server():
    s = Server()
    yield s
    s.stop()


def read_back(conn):
    """What test_tiles.outputs gives for a CSV, read from the database with OGR: sorted (rings, n_parts, area,
    z range, ids) of the plans, (plan rings, fp_id, source_id) of the members, the problems; and {rings: (gp_id,
    feature id)}."""
    ds = ogr.Open(conn)
    assert ds is not None, conn
    plans, ids = [], {}
    for f in ds.GetLayerByName("ground_plans"):
        key = plan_key(f.GetGeometryRef().ExportToWkt().replace(", ", ","))
        plans.append((key, str(f["n_parts"]), repr(f["area_m2"]), repr(f["min_z"]), repr(f["max_z"]),
                      f["building_ids"]))
        ids[key] = (f["gp_id"], f.GetFID())
    by_gp = {gp: key for key, (gp, _) in ids.items()}
    members = sorted((by_gp[f["gp_id"]], f["fp_id"], f["source_id"]) for f in ds.GetLayerByName("plan_members"))
    problems = sorted((f["source_id"], f["stage"], f["code"], f["reason"]) for f in ds.GetLayerByName("problems"))
    return sorted(plans), members, problems, ids


def into_postgis(server, src, *flags, launcher=(), check=True):
    name, conn = server.new_database()
    p = run([*launcher, BIN, "-q", "--threads", "2", *flags, "-f", "PostgreSQL", conn, src,
             "ground_plans", "plan_members", "problems"], check=check)
    return name, conn, p


def check_numbering(ids, gathered_csv_dir):
    """gp_id and ogc_fid of every plan are those a run gathering on rank 0 writes (its CSV), so 1..N."""
    with open(gathered_csv_dir / "ground_plans.csv", newline="") as f:
        gathered = {plan_key(r["WKT"]): int(r["gp_id"]) for r in csv.DictReader(f)}
    assert {k: gp for k, (gp, _) in ids.items()} == gathered
    assert all(gp == fid for gp, fid in ids.values()), "ogc_fid is not gp_id"
    assert sorted(gp for gp, _ in ids.values()) == list(range(1, len(ids) + 1))


@pytest.fixture(scope="module")
def city(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pgcity") / "city"
    tiles = generated_city(folder)
    return folder, tiles


def test_one_process_into_postgis(server, city):
    """The plain CLI into PostGIS (GDAL's ogr2ogr as always): the plans of the CSV run, ids 1..N."""
    folder, _ = city
    _, conn, _ = into_postgis(server, folder, "--tiles", "off", "--id-field", "bid")
    got = read_back(conn)
    assert len(got[0]) == COURTYARDS + 1
    assert sorted(gp for gp, _ in got[3].values()) == list(range(1, COURTYARDS + 2))
    assert len(got[1]) == sum(int(p[1]) for p in got[0])


@pytest.fixture(scope="module")
def niedersachsen_and_a_bad_tile(tmp_path_factory):
    """The 4 real tiles and a broken file last by name (the last rank's: its problem reaches rank 0, which writes
    the problems layer)."""
    folder = tmp_path_factory.mktemp("pgnds") / "tiles"
    folder.mkdir()
    for tile in sorted(NIEDERSACHSEN.glob("*.gml")):
        (folder / tile.name).symlink_to(tile)
    (folder / "LoD1_99999999_broken.gml").write_text('<?xml version="1.0"?>\n<CityModel><cityObjectMember><bldg')
    return folder


@pytest.mark.skipif(not mpi_build(), reason="no MPI in this build, or no mpirun")
@pytest.mark.parametrize("src,flags,tiles", [("city", ("--id-field", "bid"), 9), ("niedersachsen", (), 5)])
def test_four_ranks_write_into_postgis(server, city, niedersachsen_and_a_bad_tile, tmp_path, src, flags, tiles):
    folder = city[0] if src == "city" else niedersachsen_and_a_bad_tile
    _, one_conn, _ = into_postgis(server, folder, "--tiles", "off", *flags)
    one = read_back(one_conn)
    stats = tmp_path / "s.json"
    name, conn, _ = into_postgis(server, folder, "--tiles", "on", "--stats", stats, *flags, launcher=mpirun(4))
    got = read_back(conn)
    assert len(one[0]) > (COURTYARDS if src == "city" else 100)
    assert got[0] == one[0], "plans differ from the one-process run"
    assert got[1] == one[1], "plan members differ"
    assert got[2] == one[2], "problems differ"
    if src == "niedersachsen":
        assert [p for p in got[2] if p[2] == "UNREADABLE_FILE"], got[2]
    st = json.loads(stats.read_text())
    assert st["counts"]["ground_plans"] == len(got[0])
    # made in a staging schema, moved into public once every rank had committed, the staging schema gone
    assert st["writer"]["staging_schema"].startswith("groundplan_partial_"), st["writer"]
    assert staging_schemas(server, name) == []
    check_plans(got, st, 4, tiles)  # GEOS-valid, none split, buildings = members + dropped
    # the same numbering as the 4 ranks gathering on rank 0 into a CSV
    gathered = outputs(tmp_path, "gathered", folder, "--tiles", "on", *flags, launcher=mpirun(4))
    assert len(gathered[0]) == len(got[0])
    check_numbering(got[3], tmp_path / "gathered")
    # the rows of ranks 1-3 are there, their final plans never sent to rank 0 (with the bad tile, rank 3 has
    # only that one and writes nothing)
    assert sum(r["footprints"] for r in st["mpi"]["per_rank"][1:]) > 0
    # the ids' sequences are past every id written (GDAL sets them after each rank's commit; the last one sees all)
    for table, rows in (("ground_plans", len(got[0])), ("plan_members", len(got[1])), ("problems", len(got[2]))):
        assert server.psql(name, f"SELECT count(*), max(ogc_fid) FROM {table}") == (f"{rows}|{rows}" if rows else "0|")
        if rows:
            assert server.psql(name, f"SELECT last_value FROM {table}_ogc_fid_seq") == str(rows), table


TABLES = ("ground_plans", "plan_members", "problems")


def tables_in(server, name, schema):
    """The run's tables present in `schema`, comma-separated in name order."""
    return server.psql(name, "SELECT coalesce(string_agg(tablename, ',' ORDER BY tablename), '') FROM pg_tables "
                             f"WHERE schemaname = '{schema}' AND tablename IN ('ground_plans', 'plan_members', "
                             "'problems')")


def staging_schemas(server, name):
    """The staging schemas left in the database (groundplan_partial_*)."""
    got = server.psql(name, "SELECT string_agg(nspname, ',') FROM pg_namespace WHERE nspname LIKE 'groundplan%'")
    return got.split(",") if got else []


def mpi_into(server, name, conn, folder, fail, *flags):
    env = gdal_env()
    env["GROUNDPLAN_MPI_TEST_FAIL"] = fail
    return subprocess.run([*mpirun(4), "-x", "GROUNDPLAN_MPI_TEST_FAIL", BIN, "-q", "--tiles", "on", "--id-field",
                           "bid", *flags, "-f", "PostgreSQL", conn, str(folder), *TABLES],
                          capture_output=True, text=True, env=env, timeout=300)


@pytest.mark.skipif(not mpi_build(), reason="no MPI in this build, or no mpirun")
@pytest.mark.parametrize("how", ["kill", "throw"])
def test_a_rank_that_dies_before_the_commit_leaves_no_row(server, city, how):
    """Rank 2 has written its rows (not committed) and fails. Rank 0 made the tables in a staging schema, and the
    user's schema gets them only once every rank has committed. Thrown: every rank learns it and rolls back, and rank
    0 drops the staging schema (an orderly failure naming rank 2). Killed: mpirun ends every rank, each transaction is
    rolled back when its connection closes; the public schema holds no table of the run, and the staging schema that
    stays (no rank is left to drop it) says in its comment what it is, and holds no row."""
    folder, _ = city
    name, conn = server.new_database()
    p = mpi_into(server, name, conn, folder, f"2:{how}@commit")
    assert p.returncode != 0
    assert tables_in(server, name, "public") == ""
    left = staging_schemas(server, name)
    if how == "throw":
        assert "could not write" in p.stderr and "rank 2: GROUNDPLAN_MPI_TEST_FAIL" in p.stderr, p.stderr
        assert "every rank rolled back" in p.stderr and "the tables this run made are dropped" in p.stderr, p.stderr
        assert left == [], left
    else:
        assert "rank 2" in p.stderr and "signal 9" in p.stderr, p.stderr
        assert len(left) == 1 and left[0].startswith("groundplan_partial_"), left
        assert tables_in(server, name, left[0]) == ",".join(TABLES)
        for table in TABLES:
            assert server.psql(name, f"SELECT count(*) FROM {left[0]}.{table}") == "0", table
        comment = server.psql(name, f"SELECT obj_description('{left[0]}'::regnamespace)")
        assert "has not finished" in comment and f'DROP SCHEMA "{left[0]}" CASCADE' in comment, comment
        # the next run into that database says so (and writes its own tables as usual)
        env = gdal_env()
        p = subprocess.run([*mpirun(4), BIN, "--tiles", "on", "--id-field", "bid", "-f", "PostgreSQL", conn,
                            str(folder), *TABLES], capture_output=True, text=True, env=env, timeout=300)
        assert p.returncode == 0, p.stderr
        assert f"the database holds the staging schema of another run: {left[0]}: groundplan: the tables" in \
            p.stderr, p.stderr
        assert tables_in(server, name, "public") == ",".join(TABLES)
        assert staging_schemas(server, name) == left


@pytest.mark.skipif(not mpi_build(), reason="no MPI in this build, or no mpirun")
@pytest.mark.parametrize("how", ["kill", "throw", None])
def test_overwrite_replaces_the_old_tables_only_once_every_rank_has_written(server, city, tmp_path, how):
    """-overwrite over the tables of an earlier run: a run that fails (an orderly failure, or a rank killed) leaves
    the old tables as they were, rows and all; one that succeeds replaces them (the plans of a fresh run, no staging
    schema left, the id sequences past every id)."""
    folder, _ = city
    name, conn = server.new_database()
    stats = tmp_path / "s.json"
    first = mpi_into(server, name, conn, folder, "", "--stats", str(stats))
    assert first.returncode == 0, first.stderr
    assert json.loads(stats.read_text())["writer"]["staging_schema"].startswith("groundplan_partial_")
    server.psql(name, "UPDATE ground_plans SET building_ids = 'old' WHERE ogc_fid = 1")
    old = {t: server.psql(name, f"SELECT count(*) FROM {t}") for t in TABLES}
    assert int(old["ground_plans"]) > COURTYARDS
    p = mpi_into(server, name, conn, folder, f"1:{how}@commit" if how else "", "-overwrite")
    if how:
        assert p.returncode != 0
        assert server.psql(name, "SELECT building_ids FROM ground_plans WHERE ogc_fid = 1") == "old"
        assert {t: server.psql(name, f"SELECT count(*) FROM {t}") for t in TABLES} == old
        assert len(staging_schemas(server, name)) == (1 if how == "kill" else 0)
    else:
        assert p.returncode == 0, p.stderr
        assert server.psql(name, "SELECT building_ids FROM ground_plans WHERE ogc_fid = 1") != "old"
        assert {t: server.psql(name, f"SELECT count(*) FROM {t}") for t in TABLES} == old
        assert staging_schemas(server, name) == []
        rows = old["ground_plans"]
        assert server.psql(name, "SELECT last_value FROM ground_plans_ogc_fid_seq") == rows
        assert server.psql(name, "SELECT count(*) FROM pg_indexes WHERE schemaname = 'public' AND "
                                 "tablename = 'ground_plans' AND indexdef LIKE '%gist%'") == "1"


@pytest.mark.skipif(not mpi_build(), reason="no MPI in this build, or no mpirun")
def test_a_failed_run_drops_only_the_tables_it_made(server, city):
    """A problems table is there before the run (someone else's, with a row; GDAL's ogr2ogr appends to it, adding
    its columns). Rank 2 fails before the commit: ground_plans and plan_members, which rank 0 made, are dropped; the
    problems table stays, with its row and nothing of the run."""
    folder, _ = city
    name, conn = server.new_database()
    server.psql(name, "CREATE TABLE problems (note text); INSERT INTO problems VALUES ('kept')")
    env = gdal_env()
    env["GROUNDPLAN_MPI_TEST_FAIL"] = "2:throw@commit"
    p = subprocess.run([*mpirun(4), "-x", "GROUNDPLAN_MPI_TEST_FAIL", BIN, "-q", "--tiles", "on", "--id-field", "bid",
                        "-f", "PostgreSQL", conn, str(folder), "ground_plans", "plan_members", "problems"],
                       capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode != 0
    assert "the tables this run made are dropped: ground_plans, plan_members" in p.stderr, p.stderr
    assert staging_schemas(server, name) == []  # problems existed: appended in place, as GDAL's ogr2ogr appends
    present = server.psql(name, "SELECT string_agg(tablename, ',' ORDER BY tablename) FROM pg_tables WHERE "
                                "schemaname = 'public' AND tablename IN ('ground_plans', 'plan_members', 'problems')")
    assert present == "problems"
    assert server.psql(name, "SELECT note FROM problems") == "kept"


@pytest.mark.skipif(not mpi_build(), reason="no MPI in this build, or no mpirun")
def test_append_over_ranks_to_tables_with_rows(server, city):
    """-append into the tables of an earlier run (written in place): the new rows' ids come from the tables'
    sequences, as GDAL's ogr2ogr -append numbers them in one process, not from gp_id (which the earlier rows hold
    already); every row kept, no id twice, the sequences past every id."""
    folder, _ = city
    name, conn = server.new_database()
    first = mpi_into(server, name, conn, folder, "")
    assert first.returncode == 0, first.stderr
    rows = {t: int(server.psql(name, f"SELECT count(*) FROM {t}")) for t in TABLES}
    assert rows["ground_plans"] > COURTYARDS
    p = mpi_into(server, name, conn, folder, "", "-append")
    assert p.returncode == 0, p.stderr
    for t in ("ground_plans", "plan_members"):
        n = 2 * rows[t]
        assert server.psql(name, f"SELECT count(*), count(DISTINCT ogc_fid), max(ogc_fid) FROM {t}") == f"{n}|{n}|{n}"
        assert server.psql(name, f"SELECT last_value FROM {t}_ogc_fid_seq") == str(n), t
    assert staging_schemas(server, name) == []
