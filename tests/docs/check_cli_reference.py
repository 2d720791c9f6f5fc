#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The CLI's and the driver's descriptions agree: every long option `groundplan --help` lists is documented
in docs/cli.md's options tables and in the man page packaging/groundplan.1, and neither documents a long option
the CLI does not have; every open option `ogrinfo --format GroundPlan` lists is in docs/gdal-driver.md's table,
and the table names no other. Usage: check_cli_reference.py --source DIR --bin build/bin/groundplan
--plugins build/gdalplugins"""
import argparse
import os
import pathlib
import re
import subprocess
import sys


def help_options(binary):
    out = subprocess.run([binary, "--help"], capture_output=True, text=True, check=True).stdout
    # CLI11 lists an option as "  -h,--help ..." or "  --resolution FLOAT ..." at the start of a line
    return {m.group(1) for m in re.finditer(r"^\s+(?:-\w,)?(--[a-z][a-z0-9-]*)", out, re.M)}


def cli_md_options(text):
    """Long options in the first column of the tables under '## Options' of docs/cli.md."""
    section = text.split("\n## Options", 1)[1].split("\n## ", 1)[0]
    found = set()
    for line in section.splitlines():
        if line.startswith("|"):
            first = line.split("|")[1]
            found |= set(re.findall(r"(--[a-z][a-z0-9-]*)", first))
    return found


def man_options(text):
    """Long options of the man page's OPTIONS section (.B lines, groff's \\- for a dash)."""
    section = text.split(".SH OPTIONS", 1)[1].split(".SH ", 1)[0]
    found = set()
    for line in section.splitlines():
        if line.startswith(".B"):
            found |= set(re.findall(r"(--[a-z][a-z0-9-]*)", line.replace("\\-", "-")))
    return found


def driver_open_options(plugin_dir):
    env = dict(os.environ, GDAL_DRIVER_PATH=plugin_dir)
    out = subprocess.run(["ogrinfo", "--format", "GroundPlan"], capture_output=True, text=True, check=True,
                         env=env).stdout
    return set(re.findall(r'<Option name="([A-Z_]+)"', out))


def driver_md_options(text):
    """Upper-case names in the first column of the table under '## Open options' of docs/gdal-driver.md."""
    section = text.split("\n## Open options", 1)[1].split("\n## ", 1)[0]
    found = set()
    for line in section.splitlines():
        if line.startswith("|"):
            found |= set(re.findall(r"`([A-Z][A-Z_]+)`", line.split("|")[1]))
    return found


def compare(name, documented, actual, source_name, bad):
    for o in sorted(actual - documented):
        bad.append(f"{name} does not document {o} ({source_name} lists it)")
    for o in sorted(documented - actual):
        bad.append(f"{name} documents {o}, which {source_name} does not list")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True, type=pathlib.Path)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--plugins", required=True, help="the folder holding ogr_GroundPlan.so")
    a = ap.parse_args()
    cli = help_options(a.bin)
    if len(cli) < 10:
        print(f"could not read the options from {a.bin} --help (found {sorted(cli)})", file=sys.stderr)
        return 1
    docs = {"docs/cli.md": cli_md_options((a.source / "docs/cli.md").read_text()),
            "packaging/groundplan.1": man_options((a.source / "packaging/groundplan.1").read_text())}
    bad = []
    for name, opts in docs.items():
        compare(name, opts, cli, "groundplan --help", bad)
    oo = driver_open_options(a.plugins)
    if len(oo) < 10:
        bad.append(f"could not read the open options from ogrinfo --format GroundPlan (found {sorted(oo)})")
    compare("docs/gdal-driver.md", driver_md_options((a.source / "docs/gdal-driver.md").read_text()), oo,
            "ogrinfo --format GroundPlan", bad)
    print(f"groundplan --help: {len(cli)} long options; " + ", ".join(f"{n}: {len(o)}" for n, o in docs.items())
          + f"; open options: {len(oo)}")
    for b in bad:
        print("FAILED " + b, file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
