# SPDX-License-Identifier: MIT
"""The Debian package (CPack) built and unpacked in a scratch root: the CLI runs, GDAL finds the plugin in
the packaged plugin folder, and a C++ program builds against the packaged headers and libgroundplan."""
import glob
import os
import pathlib
import shutil
import subprocess

import pytest

from conftest import PLATEAU_SMALL

BUILD_DIR = os.environ.get("GROUNDPLAN_BUILD_DIR")

pytestmark = pytest.mark.skipif(not BUILD_DIR or shutil.which("cpack") is None or shutil.which("dpkg-deb") is None,
                                reason="needs the CMake build folder, cpack and dpkg-deb")


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    out = tmp_path_factory.mktemp("pkg")
    p = subprocess.run(["cpack", "-G", "DEB", "-B", str(out), "--config", f"{BUILD_DIR}/CPackConfig.cmake"],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    debs = glob.glob(str(out / "*.deb"))
    assert len(debs) == 1, debs
    info = subprocess.run(["dpkg-deb", "-I", debs[0]], capture_output=True, text=True, check=True).stdout
    assert "libgdal" in info and "libgeos" in info, "dependencies missing from the control file:\n" + info
    root = out / "root"
    subprocess.run(["dpkg-deb", "-x", debs[0], str(root)], check=True)
    return root


def _multiarch():
    return subprocess.run(["gcc", "-print-multiarch"], capture_output=True, text=True).stdout.strip() or "x86_64-linux-gnu"


def test_packaged_cli_runs(root, tmp_path):
    exe = root / "usr" / "bin" / "groundplan"
    assert exe.exists()
    p = subprocess.run([str(exe), "--version"], capture_output=True, text=True)
    assert p.returncode == 0 and "groundplan" in p.stdout
    out = tmp_path / "p.gpkg"
    p = subprocess.run([str(exe), "-f", "GPKG", str(out), str(PLATEAU_SMALL)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert out.exists()
    assert (root / "usr" / "share" / "man" / "man1" / "groundplan.1").exists()


def test_packaged_plugin_is_in_gdals_plugin_folder(root):
    plugin_dir = root / "usr" / "lib" / _multiarch() / "gdalplugins"
    assert (plugin_dir / "ogr_GroundPlan.so").exists()
    env = dict(os.environ, GDAL_DRIVER_PATH=str(plugin_dir))
    formats = subprocess.run(["ogrinfo", "--formats"], capture_output=True, text=True, env=env).stdout
    assert "GroundPlan" in formats


def test_cpp_program_builds_against_the_package(root, tmp_path):
    include = root / "usr" / "include"
    libdir = root / "usr" / "lib" / _multiarch()
    pc = (libdir / "pkgconfig" / "groundplan.pc").read_text()
    assert "-lgroundplan" in pc
    assert (libdir / "cmake" / "groundplan" / "groundplanConfig.cmake").exists()
    src = tmp_path / "two_squares.cpp"
    src.write_text(r'''
#include <groundplan/ground_plans.h>
#include <cstdio>
int main() {
  using namespace groundplan;
  std::vector<Footprint> fps(2);
  fps[0].polygons = {Polygon{{{0, 0}, {2, 0}, {2, 2}, {0, 2}}, {}}};
  fps[1].polygons = {Polygon{{{1, 1}, {3, 1}, {3, 3}, {1, 3}}, {}}};
  std::vector<Problem> problems;
  auto plans = build_ground_plans(fps, UnionParams{}, problems);
  std::printf("%zu %.6f\n", plans.size(), plans.empty() ? 0.0 : plans[0].area_m2);
  return 0;
}
''')
    exe = tmp_path / "two_squares"
    subprocess.run(["g++", "-std=c++20", f"-I{include}", str(src), f"-L{libdir}", "-lgroundplan", "-o", str(exe)],
                   check=True, capture_output=True, text=True)
    p = subprocess.run([str(exe)], capture_output=True, text=True, env=dict(os.environ, LD_LIBRARY_PATH=str(libdir)))
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == ["1", "7.000000"]


def test_packaged_qgis_plugin_is_in_qgis_plugin_folder(root):
    """Debian's QGIS finds system-wide Python plugins in /usr/share/qgis/python/plugins (its pkgDataPath)."""
    plugin = root / "usr" / "share" / "qgis" / "python" / "plugins" / "groundplan_provider"
    for name in ("__init__.py", "metadata.txt", "plugin.py", "provider.py", "algorithm.py"):
        assert (plugin / name).is_file(), name
    assert "hasProcessingProvider=yes" in (plugin / "metadata.txt").read_text()
    python_dir = root / "usr" / "lib" / "python3" / "dist-packages" / "groundplan"
    assert (python_dir / "__init__.py").is_file(), "the plugin drives the Python module: it must be packaged too"


def _elf_files(folder):
    return [p for p in folder.rglob("*") if p.is_file() and not p.is_symlink() and p.read_bytes()[:4] == b"\x7fELF"]


def test_nothing_packaged_needs_the_cuda_runtime(root):
    """The package loads where CUDA is absent: no packaged binary needs libcudart or libcuda (the CUDA backend, where
    built, is a module loaded when asked for, with the CUDA runtime linked in statically). packaging/
    check-deb-without-cuda.sh goes further: it installs the package in a Debian chroot without CUDA and runs it."""
    elfs = _elf_files(root)
    assert {p.name for p in elfs} >= {"groundplan", "ogr_GroundPlan.so"}, elfs
    for p in elfs:
        needed = [l for l in subprocess.run(["readelf", "-d", str(p)], capture_output=True, text=True,
                                            check=True).stdout.splitlines() if "(NEEDED)" in l]
        assert needed, f"{p}: no NEEDED entries read"
        assert not [l for l in needed if "libcudart" in l or "libcuda.so" in l], f"{p} needs CUDA: {needed}"


def test_cmake_install_puts_the_module_on_debians_python_path(tmp_path):
    """`cmake --install` with the default prefix (/usr/local) puts the Python module in a folder on the sys.path of
    the python3 it is built for, and the QGIS plugin in QGIS's own plugin folder."""
    if not BUILD_DIR or not (pathlib.Path(BUILD_DIR) / "python" / "groundplan").is_dir():
        pytest.skip("the Python module is not built")
    cache = (pathlib.Path(BUILD_DIR) / "CMakeCache.txt").read_text()
    if "CMAKE_INSTALL_PREFIX:PATH=/usr/local\n" not in cache:
        pytest.skip("the build is configured for another prefix than the default")
    dest = tmp_path / "dest"
    p = subprocess.run(["cmake", "--install", BUILD_DIR], capture_output=True, text=True, timeout=600,
                       env=dict(os.environ, DESTDIR=str(dest)))
    assert p.returncode == 0, p.stdout + p.stderr
    inits = list(dest.glob("usr/local/**/groundplan/__init__.py"))
    assert len(inits) == 1, inits
    folder = "/" + str(inits[0].parent.parent.relative_to(dest))
    path = subprocess.run(["/usr/bin/python3", "-c", "import sys; print('\\n'.join(sys.path))"], capture_output=True,
                          text=True, check=True, env={"PATH": "/usr/bin:/bin"}).stdout.split()
    assert folder in path, f"{folder} is not on Debian's python3 sys.path {path}"
    assert (dest / "usr/share/qgis/python/plugins/groundplan_provider/metadata.txt").is_file()
